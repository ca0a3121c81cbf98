"""The catheter model: the lumped Dahl catheter, its constant-curvature baseline, parameters."""
from model.constant_curvature import ConstantCurvature, bend_from_tendons, tendons_from_articulation
from model.dahl_catheter import (CatheterState, DahlCatheter, ModelInputError, ModelSolverError,
                                 SolverBudgetExceeded)
from model.effect_terms import EffectTerms
from model.params import CatheterParams, ParamsError

__all__ = ["CatheterParams", "CatheterState", "ConstantCurvature", "DahlCatheter", "EffectTerms",
           "ModelInputError", "ModelSolverError", "ParamsError", "SolverBudgetExceeded", "bend_from_tendons",
           "tendons_from_articulation"]
