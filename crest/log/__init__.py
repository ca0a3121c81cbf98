"""Experiment logs in the crest-log/1 format (CSV + JSON sidecar) and CAN traffic recording."""

from crest.log.bus_recorder import BusRecorder
from crest.log.log_format import FORMAT_TAG, LogFormatError, TruncatedLogWarning, catheter_dict, sidecar_path
from crest.log.log_reader import ExperimentLog, read_log, recorded_plant
from crest.log.log_writer import LogWriter

__all__ = [
    "FORMAT_TAG",
    "BusRecorder",
    "ExperimentLog",
    "LogFormatError",
    "LogWriter",
    "TruncatedLogWarning",
    "catheter_dict",
    "read_log",
    "recorded_plant",
    "sidecar_path",
]
