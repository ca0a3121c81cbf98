"""Is the drive on the bus the device the configuration's EDS describes?

Checked by SDO after boot-up:
- device type 0x1000, bits 0-15: the device profile, 402 for a CiA 402 drive;
- identity 0x1018: sub 1 vendor id, sub 2 product code, sub 3 revision number, against the
  EDS [DeviceInfo] VendorNumber, ProductNumber, RevisionNumber; sub 4 (serial) is reported;
- supported drive modes 0x6502: profile position (bit 0), homing (bit 5) and cyclic
  synchronous position (bit 7), the modes the driver uses.
"""

from __future__ import annotations

from dataclasses import dataclass

from crest.driver.cia402 import REQUIRED_SUPPORTED_MODES
from crest.driver.drive_axis import DriveAxis
from crest.driver.errors import IdentityMismatch

DEVICE_PROFILE_402 = 402


@dataclass(frozen=True)
class DriveIdentity:
    vendor_id: int
    product_code: int
    revision: int
    serial: int


def check_identity(axis: DriveAxis) -> DriveIdentity:
    """Read and check the drive's identity; IdentityMismatch names the object and both values."""
    step = "check identity"
    device_type = axis.sdo.read(0x1000, 0, step)
    if device_type & 0xFFFF != DEVICE_PROFILE_402:
        raise IdentityMismatch(axis.name, f"device type 0x1000 = 0x{device_type:08X} is device profile "
                                          f"{device_type & 0xFFFF}, not a CiA 402 drive; check the node id")
    identity = DriveIdentity(vendor_id=axis.sdo.read(0x1018, 1, step), product_code=axis.sdo.read(0x1018, 2, step),
                             revision=axis.sdo.read(0x1018, 3, step), serial=axis.sdo.read(0x1018, 4, step))
    info = axis.node.object_dictionary.device_information
    eds = axis.config.eds_path.name
    for subindex, label, actual, expected in ((1, "vendor id", identity.vendor_id, info.vendor_number),
                                              (2, "product code", identity.product_code, info.product_number),
                                              (3, "revision number", identity.revision, info.revision_number)):
        if expected is not None and actual != expected:
            raise IdentityMismatch(axis.name, f"0x1018:{subindex} {label} is 0x{actual:08X} but {eds} says "
                                              f"0x{expected:08X}; give this axis the EDS of the drive that is "
                                              "connected, or check its node id")
    supported = axis.sdo.read(0x6502, 0, step)
    if supported & REQUIRED_SUPPORTED_MODES != REQUIRED_SUPPORTED_MODES:
        raise IdentityMismatch(axis.name, f"supported drive modes 0x6502 = 0x{supported:08X} lack profile position, "
                                          "homing or cyclic synchronous position (bits 0, 5, 7); "
                                          "the driver needs all three")
    return identity
