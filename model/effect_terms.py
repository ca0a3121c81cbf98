"""The optional physical terms that extend the base Dahl catheter ("unmodelled effects").

All terms are zero by default: the model is then exactly the seed paper's. The sim plant
switches them on to play a catheter that differs from the model; the gap diagnosis fits
them to find which one a real catheter shows. Each candidate effect in `model.effects`
owns one to three of these fields. They are computed inside the one model kernel
(`model.quasi_static_kernel`), never in a copy of it.
"""
from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

# Positions in the kernel's effect vector (numba reads these as constants).
E_TENDON_COMPLIANCE = 0
E_BACKLASH = 1
E_LUMEN_COEF = 2
E_LUMEN_EXTENT = 3
E_TUBE_PLAY = 4
E_GX = 5
E_GY = 6
E_GZ = 7
E_TWIST = 8
E_RATE = 9
E_KAPPA0_X = 10
E_KAPPA0_Y = 11
E_CREEP_COMPLIANCE = 12
E_CREEP_TIME = 13
E_SENSOR_X = 14
E_SENSOR_Y = 15
E_SENSOR_Z = 16
E_TRACKER_X = 17
E_TRACKER_Y = 18
E_TRACKER_Z = 19
N_KERNEL_TERMS = 20


@dataclass(frozen=True)
class EffectTerms:
    """Physical terms beyond the base model (units in the names; 0 = off).

    tendon_compliance_mm_per_n: drive-line stretch outside the catheter, u_eff = u - c*T_drive.
    backlash_mm: dead band (play) of width w in each tendon drive train at reversals.
    lumen_compression_per_n, lumen_compression_extent_mm: lumens pushed toward the neutral axis
        under load near the base: moment arm r_i = r / (1 + c*sum_k T_k,i * exp(-s_i/extent)).
    tube_play_mm: catheter/support-tube friction: the free length lags the insertion axis by a
        play of this width at each reversal of insertion.
    gravity_m_s2: acceleration of gravity in the base frame (sag under own weight).
    twist_rad: torsion: the lumens turn by this angle from base to tip, coupling the planes.
    rate_friction_s_per_mm: velocity-strengthening friction, Fs*(1 + c*|v|), v the tendon's pull
        speed in mm/s.
    precurvature_per_mm: residual rest curvature (kx, ky) of the unactuated catheter.
    drive_creep_mm_per_n, drive_creep_time_s: viscoelastic creep of the drive line (standard
        linear solid): a stretch s_c with s_c + tau*ds_c/dt = c_creep*T_drive, in series with the
        elastic stretch, so the tip sees u - c*T_drive - s_c (quasi_static_kernel.drive_creep).
    sensor_offset_mm: the tip sensor's mount offset d in the tip frame (a coil beside or behind the
        tip centre): it turns with the tip.
    tracker_offset_mm: the tracker's registration error o in the base frame: a constant offset.
        The tip is reported as p_tip + R_tip d + o.
    """

    tendon_compliance_mm_per_n: float = 0.0
    backlash_mm: float = 0.0
    lumen_compression_per_n: float = 0.0
    lumen_compression_extent_mm: float = 10.0
    tube_play_mm: float = 0.0
    gravity_m_s2: tuple[float, float, float] = (0.0, 0.0, 0.0)
    twist_rad: float = 0.0
    rate_friction_s_per_mm: float = 0.0
    precurvature_per_mm: tuple[float, float] = (0.0, 0.0)
    drive_creep_mm_per_n: float = 0.0
    drive_creep_time_s: float = 0.2
    sensor_offset_mm: tuple[float, float, float] = (0.0, 0.0, 0.0)
    tracker_offset_mm: tuple[float, float, float] = (0.0, 0.0, 0.0)

    def __post_init__(self) -> None:
        for field in dataclasses.fields(self):
            value = getattr(self, field.name)
            values = value if isinstance(value, tuple) else (value,)
            if not all(isinstance(v, (int, float)) and math.isfinite(v) for v in values):
                raise ValueError(f"effect term '{field.name}' must be finite, got {value!r}")
        for name in ("tendon_compliance_mm_per_n", "backlash_mm", "lumen_compression_per_n",
                     "tube_play_mm", "rate_friction_s_per_mm", "drive_creep_mm_per_n"):
            if getattr(self, name) < 0:
                raise ValueError(f"effect term '{name}' must be >= 0, got {getattr(self, name)}")
        if self.lumen_compression_extent_mm <= 0:
            raise ValueError("effect term 'lumen_compression_extent_mm' must be > 0")
        if self.drive_creep_time_s <= 0:
            raise ValueError("effect term 'drive_creep_time_s' must be > 0")

    def replace(self, **changes) -> "EffectTerms":
        return dataclasses.replace(self, **changes)

    def kernel_vector(self) -> np.ndarray:
        """The terms the kernel needs, packed at the E_* positions."""
        v = np.zeros(N_KERNEL_TERMS)
        v[E_TENDON_COMPLIANCE] = self.tendon_compliance_mm_per_n
        v[E_BACKLASH] = self.backlash_mm
        v[E_LUMEN_COEF] = self.lumen_compression_per_n
        v[E_LUMEN_EXTENT] = self.lumen_compression_extent_mm
        v[E_TUBE_PLAY] = self.tube_play_mm
        v[E_GX:E_GZ + 1] = self.gravity_m_s2
        v[E_TWIST] = self.twist_rad
        v[E_RATE] = self.rate_friction_s_per_mm
        v[E_KAPPA0_X:E_KAPPA0_Y + 1] = self.precurvature_per_mm
        v[E_CREEP_COMPLIANCE] = self.drive_creep_mm_per_n
        v[E_CREEP_TIME] = self.drive_creep_time_s
        v[E_SENSOR_X:E_SENSOR_Z + 1] = self.sensor_offset_mm
        v[E_TRACKER_X:E_TRACKER_Z + 1] = self.tracker_offset_mm
        return v
