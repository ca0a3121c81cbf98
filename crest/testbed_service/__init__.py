"""The virtual testbed served as its own process: where it is (state file) and the serving loop."""

from crest.testbed_service.state_file import (ServedTestbed, TestbedAlreadyServed, claim_serving,
                                              config_digest, running_testbed, state_path)

__all__ = ["ServedTestbed", "TestbedAlreadyServed", "claim_serving", "config_digest", "running_testbed", "state_path"]
