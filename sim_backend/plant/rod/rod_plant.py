"""The rod plant: a Kirchhoff-rod catheter with frictional elastic tendons, behind the drives.

Each step (quasi-static, step_solver.py does the rod and tendons):

1. Drive train. The catheter base sees the pull x_k = the drive position minus the tendon's
   zero offset, through the drum's play if `backlash` is on (x follows u only once u leaves
   [x - w/2, x + w/2]).
2. Free length. The nodes cover the free length L out of the support tube, M nodes evenly.
   Material enters and leaves at the tube exit: state fixed to the material (tension memory,
   creep) is kept as a function of the distance from the tip and re-sampled on the new grid
   when L changes; material just emerging from the tube takes the base node's state (inside the
   straight tube the tendons neither bend nor wrap). With `tube_friction` the free length follows
   the insertion axis only once the shaft force exceeds the grip: L moves to stay within
   +-F_grip / k_shaft of the axis.
3. Solve for the drive tensions (Newton) with the friction return mapping from the last profile;
   a step that does not converge is retried in 4, 16, 64 increments of the pull.
   With a damping time tau > 0 (Kelvin-Voigt shaft material, [shaft] damping_time_s) the
   bending moment is EI (kappa - kappa_rest) + tau EI dkappa/dt. Backward Euler over an increment
   of dt [s] from the curvature kappa_n it started at turns this into the static rod with
       EI_dt = EI (1 + tau/dt),   kappa_rest_dt = (kappa_rest + (tau/dt) kappa_n) / (1 + tau/dt),
   so each increment is the same quasi-static solve (implicit, unconditionally stable; the
   shaft's mass is neglected: the curvature relaxes to the static shape with time constant tau).
4. Creep (sheath_creep): the rest curvature relaxes toward f (kappa - kappa_set),
   kappa_c += (f (kappa - kappa_set) - kappa_c) (1 - exp(-dt / tau)).
5. The tip as the tracker sees it: the last node, plus the sensor's mount offset turned by the tip
   frame (sensor_offset), plus the registration error in the base frame (tracker_offset).

Output: (tip_mm (3,), tension at the drives (4,)), the plant protocol of plant_protocol.py.
"""
from __future__ import annotations

import math

import numpy as np

from sim_backend.plant.rod.rod_description import RodDescription
from sim_backend.plant.rod.step_solver import solve_step

MIN_FREE_LENGTH_MM = 1.0
TOLERANCE_MM = 1e-7        # compatibility residual of each tendon at the solution
MAX_ITERATIONS = 100
# a step that does not converge is retried from where the last converged increment left, the
# rest of the pull moved in this many equal increments (a finer quasi-static path through the friction kinks)
SUBSTEPS = (1, 4, 16, 64)


class RodSolverError(RuntimeError):
    """The step did not converge; the message gives the inputs it was solving for."""


class RodPlant:
    """A continuum-rod catheter. No-argument construction reads configs/rod_plant.toml."""

    def __init__(self, description: RodDescription | None = None):
        self.description = description if description is not None else RodDescription.from_toml()
        d = self.description
        self._ei_nmm2 = d.bending_stiffness_nmm2
        self._zeros_mm = np.asarray(d.tendon_zero_offsets_mm, dtype=float)
        fx = d.effects
        self._drive_compliance = d.drive_compliance_mm_per_n + fx.get("tendon_elasticity", {}).get(
            "extra_compliance_mm_per_n", 0.0)
        self._play_mm = fx.get("backlash", {}).get("gear_play_mm", 0.0)
        tube = fx.get("tube_friction")
        self._tube_play_mm = tube["grip_friction_n"] / tube["shaft_stiffness_n_per_mm"] if tube else 0.0
        sensor = fx.get("sensor_offset", {})
        self._sensor_mm = np.array([sensor.get("sensor_x_mm", 0.0), sensor.get("sensor_y_mm", 0.0),
                                    sensor.get("sensor_z_mm", 0.0)])
        registration = fx.get("tracker_offset", {})
        self._registration_mm = np.array([registration.get(f"registration_{axis}_mm", 0.0) for axis in "xyz"])
        self._mu_rate = fx.get("rate_friction", {}).get("mu_rate_s_per_mm", 0.0)
        creep = fx.get("sheath_creep", {})
        self._creep_fraction = creep.get("creep_fraction", 0.0)
        self._creep_tau_s = creep.get("time_constant_s", 1.0)
        self.reset()

    # -- state ----------------------------------------------------------------------------------
    def reset(self) -> None:
        m = self.description.grid_nodes
        self.free_length_mm: float | None = None
        self.pull_mm = np.zeros(4)                 # at the catheter base, after the drive train
        self.tension_n = np.zeros((m, 4))          # tendon tension profiles, node 0 = tube exit
        self.creep_per_mm = np.zeros((m, 2))       # crept rest curvature (sheath_creep)
        self.drive_tension_n = np.zeros(4)
        self.kappa_per_mm = np.zeros((m, 2))
        self.rotation = np.tile(np.eye(3), (m, 1, 1))
        self.position_mm = np.zeros((m, 3))
        self.iterations = 0
        self._nodes_length_mm: float | None = None     # the free length the node properties were built for
        self._node_cache: dict = {}

    # -- the plant protocol ---------------------------------------------------------------------
    def step(self, dt_s: float, tendon_mm, insertion_mm: float) -> tuple[np.ndarray, np.ndarray]:
        """Advance to the drives' positions; returns (tip_mm (3,), tendon tension at the drives (4,))."""
        dt_s = max(float(dt_s), 0.0)
        u = np.asarray(tendon_mm, dtype=float).reshape(4) - self._zeros_mm
        half = 0.5 * self._play_mm
        pull = np.clip(self.pull_mm, u - half, u + half) if self.free_length_mm is not None else u.copy()
        speed_mm_s = np.abs(pull - self.pull_mm) / dt_s if dt_s > 0 else np.zeros(4)
        self._move_free_length(float(insertion_mm))
        if self._nodes_length_mm != self.free_length_mm:
            self._node_cache = self._nodes()
            self._nodes_length_mm = self.free_length_mm
        nodes = self._node_cache
        mu = self.description.mu * (1.0 + self._mu_rate * speed_mm_s)
        kappa_rest = nodes["kappa_set"] + self.creep_per_mm
        start_mm = self.pull_mm
        remaining_s = dt_s
        for substeps in SUBSTEPS:
            fraction = self._follow(self.pull_mm, pull, substeps, nodes, mu, kappa_rest, remaining_s)
            if fraction == 1.0:
                break
            remaining_s *= 1.0 - fraction
        else:
            raise RodSolverError(f"rod plant: no tendon-tension solution within {MAX_ITERATIONS} Newton iterations "
                                 f"from pull {np.round(start_mm, 4)} to {np.round(pull, 4)} mm even in "
                                 f"{SUBSTEPS[-1]} sub-steps, free length {self.free_length_mm:.2f} mm")
        if self._creep_fraction > 0.0 and dt_s > 0.0:
            relax = 1.0 - math.exp(-dt_s / self._creep_tau_s)
            self.creep_per_mm += (self._creep_fraction * (self.kappa_per_mm - nodes["kappa_set"])
                                  - self.creep_per_mm) * relax
        tip = self.position_mm[-1] + self.rotation[-1] @ self._sensor_mm + self._registration_mm
        return tip, self.drive_tension_n.copy()

    def _follow(self, start_mm, pull_mm, substeps: int, nodes: dict, mu, kappa_rest, dt_s: float) -> float:
        """Move the pull from start_mm to pull_mm in `substeps` equal increments of dt_s/substeps
        each, each from the friction state (and, with damping, the curvature) the last one left.
        Returns the fraction of the increments done: 1.0, or less if one did not converge (the
        state is then the last converged increment's)."""
        ei, rest = nodes["ei"], kappa_rest
        tau_over_dt = self.description.damping_time_s * substeps / dt_s if dt_s > 0.0 else 0.0
        for j in range(1, substeps + 1):
            target = start_mm + (pull_mm - start_mm) * (j / substeps)
            tension = np.empty_like(self.tension_n)
            drive = self.drive_tension_n.copy()
            kappa = self.kappa_per_mm.copy()
            if tau_over_dt > 0.0:     # Kelvin-Voigt by backward Euler (module doc, step 3)
                ei = nodes["ei"] * (1.0 + tau_over_dt)
                rest = (kappa_rest + tau_over_dt * self.kappa_per_mm) / (1.0 + tau_over_dt)
            iterations = solve_step(nodes["h_mm"], ei, nodes["r"], nodes["give"], nodes["cos_phi"], nodes["sin_phi"],
                                    nodes["ea_axial"], rest, nodes["kappa_set"], nodes["weight"],
                                    self._drive_compliance, self.description.tendon_axial_stiffness_n, mu,
                                    self.description.friction_n_per_mm, target, self.tension_n, drive, tension,
                                    kappa, self.rotation, self.position_mm, TOLERANCE_MM, MAX_ITERATIONS)
            if iterations < 0:
                return (j - 1) / substeps
            self.iterations = iterations
            self.tension_n = tension
            self.drive_tension_n = drive
            self.kappa_per_mm = kappa
            self.pull_mm = target
        return 1.0

    # -- free length and the grid ---------------------------------------------------------------
    def _move_free_length(self, insertion_mm: float) -> None:
        target = max(insertion_mm, MIN_FREE_LENGTH_MM)
        if self.free_length_mm is None:
            self.free_length_mm = target
            return
        old = self.free_length_mm
        new = float(np.clip(old, target - self._tube_play_mm, target + self._tube_play_mm))
        new = max(new, MIN_FREE_LENGTH_MM)
        if new == old:
            return
        m = self.description.grid_nodes
        # distance from the tip, increasing: reversed node order
        from_tip_old = old - np.linspace(0.0, old, m)[::-1]
        from_tip_new = new - np.linspace(0.0, new, m)[::-1]
        for name in ("tension_n", "creep_per_mm"):
            values = getattr(self, name)[::-1]
            resampled = np.column_stack([np.interp(from_tip_new, from_tip_old, values[:, c])
                                         for c in range(values.shape[1])])
            setattr(self, name, np.ascontiguousarray(resampled[::-1]))
        self.free_length_mm = new

    def _nodes(self) -> dict:
        """Per-node properties over the current free length (s from the tube exit, sigma from the tip)."""
        fx = self.description.effects
        m = self.description.grid_nodes
        length = self.free_length_mm
        s = np.linspace(0.0, length, m)
        from_tip = length - s
        h = length / (m - 1)
        ei = np.full(m, self._ei_nmm2)
        if "stiffness_step" in fx:
            step = fx["stiffness_step"]
            ei[from_tip <= step["distance_from_tip_mm"]] *= step["stiffness_ratio"]
        r = self.description.tendon_offset_mm + fx.get("lumen_offset_drift", {}).get("tip_offset_change_mm", 0.0) * s / length
        helix = fx.get("torsion", {}).get("helix_rad_per_mm", 0.0)
        phi = np.arange(4) * (np.pi / 2) + helix * s[:, None]
        give = np.zeros(m)
        if "lumen_compression" in fx:
            wall = fx["lumen_compression"]
            give[s <= wall["soft_wall_length_mm"]] = wall["radial_compliance_mm_per_n"]
        ea_axial = np.full(m, self.description.axial_stiffness_n)
        if "sheath_compression" in fx:
            soft = fx["sheath_compression"]
            ea_axial[s <= soft["soft_length_mm"]] = soft["soft_axial_stiffness_n"]
        pre = fx.get("precurvature", {})
        kappa_set = np.tile([pre.get("rest_kappa_x_per_mm", 0.0), pre.get("rest_kappa_y_per_mm", 0.0)], (m, 1))
        weight = np.zeros((m, 3))
        if "gravity" in fx:
            g = fx["gravity"]
            direction = np.deg2rad(g["direction_deg"])
            lumped = np.full(m, h)
            lumped[[0, -1]] = 0.5 * h
            weight[:, 0] = g["load_n_per_mm"] * lumped * np.cos(direction)
            weight[:, 1] = g["load_n_per_mm"] * lumped * np.sin(direction)
        return {"h_mm": h, "ei": ei, "r": r, "give": give, "cos_phi": np.cos(phi), "sin_phi": np.sin(phi),
                "ea_axial": ea_axial, "kappa_set": kappa_set, "weight": weight}
