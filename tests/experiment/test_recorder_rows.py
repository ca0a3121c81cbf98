"""A recorded row holds only the drives' answers to its SYNC: an axis that did not answer has empty
position (and, for a tendon, force) cells, never its last known values again."""
import math

import numpy as np

from crest.driver import AXIS_ORDER, Cia402State, CycleSample
from crest.experiment.recorder import measured_answers
from crest.log import LogWriter, catheter_dict, read_log

# tendon2 and the insertion drive did not answer this SYNC; their values are the last ones received
SAMPLE = CycleSample(t_s=12.5, target_mm=(1.0, 2.0, 3.0, 4.0, 50.0), position_mm=(1.1, 2.1, 3.1, 4.1, 49.9),
                     tension_n=(5.0, 6.0, 7.0, 8.0, 0.5), states=(Cia402State.OPERATION_ENABLED,) * 5,
                     fresh=(True, False, True, True, False))


def test_an_axis_without_an_answer_is_nan_in_position_and_tension_in_axis_order():
    position_mm, tension_n = measured_answers(SAMPLE)
    assert AXIS_ORDER == ("tendon1", "tendon2", "tendon3", "tendon4", "insertion")   # the order of `fresh`
    assert [math.isnan(value) for value in position_mm] == [False, True, False, False, True]
    assert [math.isnan(value) for value in tension_n] == [False, True, False, False, True]
    assert [position_mm[k] for k in (0, 2, 3)] == [1.1, 3.1, 4.1]
    assert [tension_n[k] for k in (0, 2, 3)] == [5.0, 7.0, 8.0]


def test_the_row_written_from_them_has_those_cells_empty_and_the_others_measured(tmp_path):
    path = tmp_path / "row.csv"
    position_mm, tension_n = measured_answers(SAMPLE)
    with LogWriter(path, catheter=catheter_dict(flexible_length_mm=80.0, tendon_offset_mm=2.5, outer_diameter_mm=6.0),
                   sample_rate_hz=100.0, source="unit test", tendon_force=True) as writer:
        writer.write(0.0, SAMPLE.tendon_target_mm, SAMPLE.insertion_target_mm, position_mm[:4], position_mm[4],
                     tendon_force_n=tension_n[:4])
    row = dict(zip(*(line.split(",") for line in path.read_text().splitlines())))
    assert (row["tendon_pos_2"], row["insertion_pos"], row["tendon_force_2"]) == ("", "", "")
    assert (row["tendon_pos_1"], row["tendon_force_4"], row["tendon_cmd_2"], row["insertion_cmd"]) == \
        ("1.1", "8.0", "2.0", "50.0")
    log = read_log(path)
    np.testing.assert_array_equal(log.tendon_pos_mm[0], [1.1, np.nan, 3.1, 4.1])
    np.testing.assert_array_equal(log.tendon_force_n[0], [5.0, np.nan, 7.0, 8.0])
