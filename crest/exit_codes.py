"""Process exit codes of the `crest` CLI: each safety-stop cause has its own."""
from enum import IntEnum


class ExitCode(IntEnum):
    OK = 0
    ERROR = 1              # bad input or an unexpected error; nothing moved or everything stopped
    USAGE = 2              # argparse's own code for bad command-line arguments
    INTERRUPTED = 3        # Ctrl-C (SIGINT)
    TERMINATED = 4         # SIGTERM (e.g. `kill PID`, a supervisor or a service manager stopping crest)
    EMCY = 10              # a drive sent an emergency message
    HEARTBEAT_LOST = 11    # a drive's heartbeat stopped
    FOLLOWING_ERROR = 12   # an axis lagged beyond its following-error window
    TENSION_LIMIT = 13     # a tendon exceeded its maximum tension
    SDO_FAILURE = 14       # an SDO request failed or timed out
    BUS_ERROR = 15         # CAN error frames or bus-off
    TRACKER_LOST = 16      # no valid tip sample for longer than allowed in a closed-loop run
    EXCEPTION = 17         # an unexpected exception in the control loop
    CONFIG = 18            # invalid configuration
