"""A result on the virtual testbed says which plant it came from: the Dahl family (the controller's own model
with other parameters, in family) or the rod family (written independently of `model`, out of family).
`crest status` names the plant of the testbed it opens, of its own or served by another process; the
served testbed writes it into its state file, where the commands that join it read it."""
from crest.config import default_config_path
from crest.exit_codes import ExitCode
from served_testbed import relaxed_config, start_served_testbed, stop
from tests.cli.cli_runner import crest

ROD_PLANT = default_config_path().parent / "rod_plant.toml"


def plant_line(stdout: str) -> str:
    lines = [line for line in stdout.splitlines() if line.startswith("plant: ")]
    assert len(lines) == 1, stdout
    return lines[0]


def test_status_names_the_default_dahl_plant_in_family_and_the_rod_plant_out_of_family(tmp_path):
    env = {"XDG_RUNTIME_DIR": str(tmp_path / "runtime")}
    config = relaxed_config(tmp_path / "config")
    default = crest("status", "--config", str(config), env=env)
    rod = crest("status", "--config", str(config), "--plant-config", str(ROD_PLANT), env=env)
    assert default.returncode == rod.returncode == ExitCode.OK, default.stderr + rod.stderr
    assert plant_line(default.stdout).startswith("plant: Dahl family") and "in family" in default.stdout
    assert "out of family" not in default.stdout
    assert plant_line(rod.stdout).startswith("plant: rod family") and "out of family" in rod.stdout


def test_a_command_joining_a_served_rod_testbed_from_another_process_names_its_plant(tmp_path):
    served = start_served_testbed(tmp_path, None, "--plant-config", str(ROD_PLANT), "--effect", "backlash")
    try:
        served_plant = served.state["plant"]
        status = served.crest("status", "--config", str(served.config))
    finally:
        stop(served.process)
    out, _ = served.process.communicate()
    assert "plant:      rod family" in out       # what `crest testbed serve` printed when it started
    assert served_plant.startswith("rod family") and "with backlash" in served_plant and "out of family" in served_plant
    assert status.returncode == ExitCode.OK, status.stderr
    assert plant_line(status.stdout) == f"plant: {served_plant}"
