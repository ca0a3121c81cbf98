"""A candidate unmodelled effect: one to three parameters that switch on physical terms of the model.

Every effect has the same small interface, so the sim plant switches any of them on from
configuration and the gap diagnosis fits, ranks and combines them without special cases.
"""
from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass

from model.effect_terms import EffectTerms


@dataclass(frozen=True)
class CandidateEffect:
    """An augmentation of the base Dahl model.

    id: canonical id (e.g. "backlash").
    physics: what it models and how, one or two sentences.
    param_names: names with units, in the order of `typical`, `lower` and `upper`.
    typical: a clearly visible magnitude on the default catheter (used by plants and drills).
    lower, upper: the physical range (fit bounds); a fit that ends at a bound other than 0 (off)
    wanted more than the effect can physically be, and is implausible.
    signature: the residual pattern it leaves when it is missing from a model.
    signature_region: where in the motion adding it must remove error (a region the gap
    diagnosis knows, see model.gap.plausibility; "every region": it removes error everywhere), ""
    where the signature names no such region.
    apply: (terms, values) -> terms with this effect's fields set.
    """

    id: str
    physics: str
    param_names: tuple[str, ...]
    typical: tuple[float, ...]
    lower: tuple[float, ...]
    upper: tuple[float, ...]
    signature: str
    signature_region: str
    apply: Callable[[EffectTerms, tuple[float, ...]], EffectTerms]

    def __post_init__(self) -> None:
        n = len(self.param_names)
        if not 1 <= n <= 3 or not len(self.typical) == len(self.lower) == len(self.upper) == n:
            raise ValueError(f"effect {self.id}: 1-3 parameters with typical, lower and upper for each")

    def values_from(self, params: Mapping[str, float]) -> tuple[float, ...]:
        """Parameter values from a mapping by name; unknown names and out-of-range values raise."""
        unknown = set(params) - set(self.param_names)
        if unknown:
            raise ValueError(f"effect {self.id}: unknown parameter(s) {sorted(unknown)}; "
                             f"expected {list(self.param_names)}")
        values = tuple(float(params.get(name, typ)) for name, typ in zip(self.param_names, self.typical))
        for name, value, low, high in zip(self.param_names, values, self.lower, self.upper):
            if not low <= value <= high:
                raise ValueError(f"effect {self.id}: {name} = {value} is outside its physical range [{low}, {high}]")
        return values

    def at_limit(self, values: tuple[float, ...], tolerance: float = 0.01) -> list[str]:
        """Names of the parameters at a bound other than 0: within `tolerance` of the range width and
        of the bound itself, |value - bound| <= tolerance * min(high - low, |bound|). A range over
        orders of magnitude (a time from 0.01 s to 5 s) would otherwise put a fifth of its decade next
        to the small bound: 0.056 s counted as at 0.01 s, and a true 0.057 s lag was rejected."""
        return [name for name, value, low, high in zip(self.param_names, values, self.lower, self.upper)
                if any(bound != 0.0 and abs(value - bound) <= tolerance * min(high - low, abs(bound))
                       for bound in (low, high))]

    def terms(self, values: tuple[float, ...], base: EffectTerms = EffectTerms()) -> EffectTerms:
        """`base` with this effect switched on at `values`."""
        return self.apply(base, tuple(float(v) for v in values))
