"""What the paper reproduction runs: the catheter, the element count and the sweeps."""
from __future__ import annotations

from dataclasses import dataclass

from model import CatheterParams


@dataclass(frozen=True)
class PaperSettings:
    """Inputs of every study of `crest paper` (seed paper sections III and IV).

    params: the catheter (configs/catheter.toml by default); its `mu` is the friction model's
        coefficient in Figs. 3.1, 3.2, 4.3 and 4.4, and is replaced by each value of
        `mu_sweep` in Figs. 4.1 and 4.2 (Fsc stays as configured).
    n_elements: lumped elements (the paper uses 20, section III).
    mu_sweep: capstan friction coefficients of Figs. 4.1 and 4.2, ascending.
    circle_articulations_deg: articulation angles of the circles of Fig. 4.3, ascending; the
        constant-curvature circle plane moves toward the base as they grow (paper IV).
    history_move_deg: size of the left/right moves of Fig. 4.4 from 180 deg [deg].
    step_deg: sample spacing of every articulation path [deg]; the model sub-steps further.
    """

    params: CatheterParams
    n_elements: int = 20
    mu_sweep: tuple[float, ...] = (0.0, 0.1, 0.2, 0.3, 0.4)
    circle_articulations_deg: tuple[float, ...] = (45.0, 90.0, 135.0, 180.0, 225.0)
    history_move_deg: float = 15.0
    step_deg: float = 1.0

    def __post_init__(self) -> None:
        for name in ("mu_sweep", "circle_articulations_deg"):
            values = getattr(self, name)
            if len(values) < 2 or any(b <= a for a, b in zip(values, values[1:])):
                raise ValueError(f"paper settings '{name}' must hold at least two ascending values, got {values!r}")
        if not self.step_deg > 0 or not self.history_move_deg > 0:
            raise ValueError(f"paper settings 'step_deg' ({self.step_deg}) and 'history_move_deg' "
                             f"({self.history_move_deg}) must be > 0")
