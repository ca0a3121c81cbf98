"""A command imports only what it needs: every start of `crest` is a person's wait (and each CLI
test's). The live view's server (bokeh, tornado), the reports' figures (matplotlib), the EKF
(filterpy, which imports scipy.stats and matplotlib) and the other commands' modules cost seconds
together at every start on this machine's kind."""
import pytest

from cli_runner import crest
from crest.exit_codes import ExitCode

NOT_NEEDED = ("bokeh", "tornado", "matplotlib", "filterpy", "scipy.stats",      # view, figures, EKF
              "crest.view.live_view", "crest.reports", "crest.gap", "crest.bench", "crest.paper",
              "control.benchmark")                                              # other commands


def imported_modules(stderr: str) -> set[str]:
    """The modules listed by Python's import profile (PYTHONPROFILEIMPORTTIME, as `python -X importtime`)."""
    return {line.rsplit("|", 1)[-1].strip() for line in stderr.splitlines() if line.startswith("import time:")}


@pytest.mark.parametrize("command,code", [
    (("status",), ExitCode.OK),                                                # boots the virtual testbed
    (("run", "builtin:sweep", "--periods", "1.5", "--fast"), ExitCode.ERROR),  # refused before boot
])
def test_a_command_without_view_figures_or_estimator_never_imports_them(command, code):
    result = crest(*command, env={"PYTHONPROFILEIMPORTTIME": "1"})
    assert result.returncode == code and "Traceback" not in result.stderr, result.stderr[-2000:]
    modules = imported_modules(result.stderr)
    assert "crest.session" in modules and "crest.cli.common_options" in modules   # the profile lists them
    unneeded = sorted(module for module in modules
                      if any(module == name or module.startswith(name + ".") for name in NOT_NEEDED))
    assert unneeded == []
