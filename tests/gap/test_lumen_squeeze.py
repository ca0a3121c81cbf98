"""The diagnosis reads the largest summed drive tension from the training logs and rejects a lumen
compression that would push a lumen more than half way to the neutral axis (`MAX_LUMEN_SQUEEZE`).

A Dahl plant whose lumen compression is 0.3 /N (inside the catalog's range, [0, 0.5]) at the ~10 N
the short excitation reaches would shrink the arm at the base to about a quarter of the lumen
offset: no wall gives that far, so the fit that finds it is not a plausible lumen compression. The
squeeze is taken where the fits' model has its first element's centre (`lumen_squeeze`)."""
import dataclasses
import tempfile
from pathlib import Path

from crest.gap.log_diagnosis import diagnose_logs
from crest.gap.log_recordings import load_recordings
from model.gap.plausibility import MAX_LUMEN_SQUEEZE, lumen_squeeze
from tests.gap.conftest import TEST_SETTINGS, record_case


def test_a_lumen_compression_squeezing_past_half_way_is_rejected_from_the_logged_tensions():
    with tempfile.TemporaryDirectory() as folder:
        train, holdout = record_case(Path(folder), {"lumen_compression": (0.3, 20.0)})
        recording = load_recordings([train])[0]
        largest_n = recording.max_summed_tension_n
        element_mm = recording.flexible_length_mm / TEST_SETTINGS.resolution.n_elements
        result = diagnose_logs([train], [holdout],
                               settings=dataclasses.replace(TEST_SETTINGS, effects=("lumen_compression",)))
    candidate, = result["candidates"]
    params = candidate["params"]
    squeeze = lumen_squeeze((params["coef_per_n"], params["extent_mm"]), largest_n, element_mm)
    assert squeeze > MAX_LUMEN_SQUEEZE       # the fit found a squeezing compression
    assert any("half way to the" in reason for reason in candidate["rejected"]), candidate["rejected"]
    assert result["verdict"]["effect"] != "lumen_compression"
