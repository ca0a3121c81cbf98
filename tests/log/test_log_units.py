"""The sidecar names every column's unit, so a reader that does not know crest (pandas, a
spreadsheet) finds it; logs written before the units were added still read."""

import json
from pathlib import Path

import pytest

from crest.log import LogFormatError, LogWriter, catheter_dict, read_log

CATHETER = catheter_dict(flexible_length_mm=80.0, tendon_offset_mm=2.5, outer_diameter_mm=6.0)
EXPECTED_UNITS = {"t": "s",
                  **{f"tendon_cmd_{k}": "mm" for k in range(1, 5)}, "insertion_cmd": "mm",
                  **{f"tendon_pos_{k}": "mm" for k in range(1, 5)}, "insertion_pos": "mm",
                  "tip_x": "mm", "tip_y": "mm", "tip_z": "mm",
                  **{f"tendon_force_{k}": "N" for k in range(1, 5)},
                  "tip_ref_x": "mm", "tip_ref_y": "mm", "tip_ref_z": "mm"}


def _write(path: Path, **groups) -> Path:
    with LogWriter(path, catheter=CATHETER, sample_rate_hz=100.0, source="unit test", **groups) as writer:
        writer.write(0.0, [1, 0, -1, 0], 50, [1, 0, -1, 0], 50, [0.5, 0.0, 49.9],
                     tendon_force_n=[2, 1, 2, 1] if groups.get("tendon_force") else None,
                     tip_ref_mm=[0.5, 0.0, 50.0] if groups.get("tip_ref") else None)
    return path


@pytest.mark.parametrize("groups", [{}, {"tendon_force": True}, {"tendon_force": True, "tip_ref": True}])
def test_every_column_of_the_header_has_its_unit_in_the_sidecar(tmp_path: Path, groups: dict):
    path = _write(tmp_path / "log.csv", **groups)
    header = path.read_text().splitlines()[0].split(",")
    sidecar = json.loads(path.with_suffix(".json").read_text())
    assert list(sidecar["units"]) == header
    assert sidecar["units"] == {name: EXPECTED_UNITS[name] for name in header}
    assert read_log(path).sidecar["units"] == sidecar["units"]


def test_a_sidecar_without_units_still_reads(tmp_path: Path):
    path = _write(tmp_path / "log.csv")
    sidecar_path = path.with_suffix(".json")
    sidecar = json.loads(sidecar_path.read_text())
    del sidecar["units"]
    sidecar_path.write_text(json.dumps(sidecar))
    assert len(read_log(path)) == 1


@pytest.mark.parametrize(("units", "problem"), [
    ({"tip_x": "m"}, "units.tip_x is 'm', but crest-log/1 stores tip_x in 'mm'"),
    ({"tendon_force_1": "kgf"}, "units.tendon_force_1 is 'kgf'"),
    ({"tip_w": "mm"}, "units names 'tip_w'"),
    (["mm"], "'units' must be a JSON object"),
])
def test_a_unit_other_than_the_formats_is_refused(tmp_path: Path, units, problem: str):
    path = _write(tmp_path / "log.csv")
    sidecar_path = path.with_suffix(".json")
    sidecar = json.loads(sidecar_path.read_text())
    sidecar["units"] = {**sidecar["units"], **units} if isinstance(units, dict) else units
    sidecar_path.write_text(json.dumps(sidecar))
    with pytest.raises(LogFormatError, match="log.json: ") as raised:
        read_log(path)
    assert problem in str(raised.value)
