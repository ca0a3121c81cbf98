"""A warning reaches the operator as one line, `crest: warning: MESSAGE`, without Python's file, category
and source line; --debug keeps Python's own format."""
from cli_runner import crest, record_short_run


def killed_writers_log(tmp_path):
    """A recorded log whose last line stops mid-row, as a writer killed mid-write leaves it."""
    log = record_short_run(tmp_path)
    text = log.read_text()
    log.write_text(text[:text.rindex("\n", 0, len(text) - 1) + 8])     # the last row cut after 7 characters
    return log, len(text[:-1].splitlines())


def test_a_truncated_log_is_one_warning_line_and_the_fit_goes_on(tmp_path):
    log, last_line = killed_writers_log(tmp_path)
    result = crest("fit", str(log), "--dynamics", "off", "--out", str(tmp_path / "fit.toml"))
    assert result.returncode == 0, result.stderr
    warnings = [line for line in result.stderr.splitlines() if "warning" in line.lower()]
    assert warnings == [f"crest: warning: {log}, line {last_line}: the last line has no newline (the writer was "
                        "killed mid-write); it is dropped"], result.stderr
    assert "TruncatedLogWarning" not in result.stderr and ".py:" not in result.stderr
    assert (tmp_path / "fit.toml").is_file()


def test_debug_keeps_pythons_warning_format(tmp_path):
    log, _ = killed_writers_log(tmp_path)
    result = crest("fit", str(log), "--dynamics", "off", "--out", str(tmp_path / "fit.toml"), "--debug")
    assert result.returncode == 0, result.stderr
    assert "TruncatedLogWarning: " in result.stderr and "crest: warning:" not in result.stderr
