"""crest: the CREST testbed driver, tracker, experiment logs and the operator CLI."""
from importlib import metadata

try:
    __version__ = metadata.version("crest-hil")
except metadata.PackageNotFoundError:  # running from a source tree that is not installed
    __version__ = "0.0.0+source"
