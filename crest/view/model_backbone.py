"""The catheter backbone the model predicts from the measured axis positions.

The view draws the constant-curvature shape (model.ConstantCurvature, seed paper I.A): the
tendon pairs give the bend theta*(cos phi, sin phi) = ((u1 - u3)/2, (u2 - u4)/2)/r, the insertion
axis position is the free length. It is stateless, so a decimated stream of samples (the view
sees about 30 of them a second) draws the same shape as the full one; the Dahl model's friction
state would need every cycle, and running it belongs to the loop, not to a screen.
"""
from __future__ import annotations

import dataclasses

import numpy as np

from model import CatheterParams, ConstantCurvature

BACKBONE_POINTS = 21


class ModelBackbone:
    def __init__(self, tendon_offset_mm: float) -> None:
        self._model = ConstantCurvature(dataclasses.replace(CatheterParams(), tendon_offset_mm=tendon_offset_mm))

    def points_mm(self, tendon_position_mm, insertion_position_mm: float) -> np.ndarray:
        """(BACKBONE_POINTS, 3) points from the tube exit to the predicted tip."""
        return self._model.backbone_mm(np.asarray(tendon_position_mm, dtype=float),
                                       max(float(insertion_position_mm), 0.0), BACKBONE_POINTS)
