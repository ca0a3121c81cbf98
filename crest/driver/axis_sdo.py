"""SDO access to one drive, typed by its EDS, with failures that name the axis and the step.

Values are encoded and decoded with the data type the EDS gives the object (0x607A is
INTEGER32, 0x6040 UNSIGNED16, ...). A request that the drive aborts or does not answer within
the configured ``sdo_timeout_s`` raises ``SdoFailure``; a value that reads back different from
what was written raises ``ReadBackMismatch``.
"""

from __future__ import annotations

import canopen
from canopen.objectdictionary import ODVariable
from canopen.sdo import SdoAbortedError, SdoCommunicationError

from crest.driver.errors import DriveError, ReadBackMismatch, SdoFailure


class AxisSdo:
    """SDO client of the drive of axis ``axis`` (a canopen RemoteNode already on the network)."""

    def __init__(self, axis: str, node: canopen.RemoteNode, timeout_s: float) -> None:
        self.axis = axis
        self.node = node
        self.timeout_s = timeout_s
        node.sdo.RESPONSE_TIMEOUT = timeout_s
        node.sdo.MAX_RETRIES = 1  # one request; a drive that does not answer in time has failed

    def variable(self, index: int, subindex: int = 0) -> ODVariable:
        variable = self.node.object_dictionary.get_variable(index, subindex)
        if variable is None:
            raise DriveError(self.axis, f"object 0x{index:04X}:{subindex:02X} is not in the EDS "
                                        f"{self.node.object_dictionary.device_information.product_name!r}; "
                                        "use the EDS of this drive in the configuration")
        return variable

    def read(self, index: int, subindex: int, step: str) -> int:
        """Upload index:subindex; ``step`` says what for (it goes into the error message)."""
        variable = self.variable(index, subindex)
        try:
            data = self.node.sdo.upload(index, subindex)
        except (SdoAbortedError, SdoCommunicationError) as error:
            raise self._failure("read", index, subindex, None, step, error) from error
        return variable.decode_raw(data)

    def write(self, index: int, subindex: int, value: int, step: str) -> None:
        """Download ``value`` to index:subindex."""
        data = self.variable(index, subindex).encode_raw(value)
        try:
            self.node.sdo.download(index, subindex, data)
        except (SdoAbortedError, SdoCommunicationError) as error:
            raise self._failure("write", index, subindex, value, step, error) from error

    def write_verified(self, index: int, subindex: int, value: int, step: str) -> None:
        """Download, upload again and compare."""
        self.write(index, subindex, value, step)
        read_back = self.read(index, subindex, step)
        if read_back != value:
            raise ReadBackMismatch(self.axis, f"{step}: 0x{index:04X}:{subindex:02X} was written {value} "
                                              f"(0x{value & 0xFFFFFFFF:X}) but reads back {read_back} "
                                              f"(0x{read_back & 0xFFFFFFFF:X}); the drive did not take the value")

    def _failure(self, verb: str, index: int, subindex: int, value: int | None, step: str,
                 error: SdoAbortedError | SdoCommunicationError) -> SdoFailure:
        what = f"SDO {verb} 0x{index:04X}:{subindex:02X}" + (f" = {value}" if value is not None else "")
        if isinstance(error, SdoAbortedError):
            why = f"aborted by the drive with 0x{error.code:08X} ({SdoAbortedError.CODES.get(error.code, 'vendor specific')})"
            remedy = "check the value against the drive's manual"
        else:
            why = f"no answer within {self.timeout_s:g} s"
            remedy = "check that the drive is powered, on the bus and not in NMT STOPPED"
        return SdoFailure(self.axis, f"{what} ({step}) failed: {why}; {remedy}")
