"""`crest fit --fit-rate-hz`: the logs are fitted at the rate asked for, over as many seconds of log as at
the default rate, and a rate that is not a number > 0 is refused before any log is read."""
import json

import pytest

from cli_runner import crest, record_short_run
from crest.exit_codes import ExitCode
from crest.log import read_log


def test_a_fit_at_50_hz_uses_every_other_row_of_a_100_hz_log(tmp_path):
    log = record_short_run(tmp_path)
    rows = len(read_log(log))
    result = crest("fit", str(log), "--dynamics", "off", "--fit-rate-hz", "50", "--out", str(tmp_path / "fit.toml"),
                   "--json", str(tmp_path / "fit.json"))
    assert result.returncode == 0, result.stderr
    sampling = json.loads((tmp_path / "fit.json").read_text())["sampling"]
    assert sampling["fit_rate_hz"] == 50.0
    assert sampling["max_fit_samples"] == 12000                 # 2400 at 10 Hz: the same 240 s of log
    (train,) = sampling["train"]
    assert train["rows"] == rows and train["decimation"] == 2   # the 100 Hz SYNC's rows, every other one
    assert train["rows_used"] == (rows + 1) // 2
    assert "decimated to about 50 Hz" in (tmp_path / "fit.toml").read_text()
    # the fitted catheter says which plant its log came from: the default Dahl plant, the model's own
    plant = "logs recorded on the virtual testbed, plant: Dahl family"
    assert f"# {plant}" in (tmp_path / "fit.toml").read_text() and plant in result.stdout
    assert "in family" in result.stdout


@pytest.mark.parametrize("rate", ["0", "-10", "nan", "fast"])
def test_a_fit_rate_that_is_not_a_positive_number_is_refused_before_any_log_is_read(tmp_path, rate):
    result = crest("fit", str(tmp_path / "missing.csv"), "--fit-rate-hz", rate, "--out", str(tmp_path / "fit.toml"))
    assert result.returncode == ExitCode.USAGE, result.stderr
    assert f"--fit-rate-hz: expected a number > 0, got '{rate}'" in result.stderr
    assert "no such file" not in result.stderr and "Traceback" not in result.stderr
    assert not (tmp_path / "fit.toml").exists()
