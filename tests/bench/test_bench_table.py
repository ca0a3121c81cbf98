"""`crest bench`'s table of a full-stack run: every figure the bench measured is in its row."""
from crest.cli.bench_command import format_table

STACK = {"sync_rate_hz_nominal": 500.0, "duration_s": 60.0, "testbed": "its own process",
         "master_scheduling": "real-time (SCHED_FIFO, priority 20)", "testbed_scheduling": "real-time",
         "controller": "dahl", "commands_in_own_process": True, "achieved_rate_hz": 499.9,
         "jitter_p50_ms": 0.02, "jitter_p99_ms": 0.2, "missed_cycles": 0, "missed_woke_late": 0,
         "missed_overran": 0, "bus_load_mean": 0.66,
         "bus_bitrate_bit_s": 1_000_000, "cycles_held_for_a_command": 0, "cycles_without_every_answer": 3,
         "answer_latency": {"answered": 29997, "unanswered": 3, "p50_ms": 1.01, "p99_ms": 1.55,
                            "p99_9_ms": 1.83, "longest_ms": 7.1},
         "hypervisor": {"steal_ms_per_cpu": {"0": 0.0, "1": 10.0}, "resolution_ms": 10.0},
         "stopped": None}
FLOOR = {"duration_s": 60.0, "period_s": 0.001, "probe": "real-time", "wakeups": 120000, "stalls": 2,
         "stall_threshold_s": 0.0005, "stalls_over_1_ms": 1, "longest_ms": 3.5,
         "stalls_over_1_ms_per_cpu": {"0": 1, "1": 1}, "stalls_over_1_ms_on_every_cpu": 1}


def test_the_full_stack_row_names_late_answers_and_the_answer_latency_and_fails_the_goal_on_them():
    table = format_table({"full_stack": {"machine_floor": FLOOR, "500_hz_testbed_process": STACK}})
    row = next(line for line in table.splitlines() if line.startswith("| Full stack at 500 Hz"))
    assert "3 cycles without every drive's answer in time" in row
    assert "0 missed (0 woke late, 0 after an overrun)" in row
    assert "answers 1.01 / 1.55 / 1.83 / 7.10 ms after the SYNC" in row
    assert "taken by the hypervisor during the run: CPU 0 0 ms, CPU 1 10 ms (to 10 ms)" in row
    assert row.rstrip().endswith("| NO |")          # 0 SYNCs missed, but 3 answers late
    floor = next(line for line in table.splitlines() if line.startswith("| Machine floor"))
    assert "1 stalls over 1 ms on any CPU" in floor and "CPU 0: 1, CPU 1: 1; 1 on every CPU at once" in floor


def test_the_profiled_run_shows_each_process_cpu_by_thread_and_where_each_thread_was_or_why_there_is_none():
    cycle = {"tid": 11, "name": "MainThread", "cpu_user": 0.3, "cpu_kernel": 0.1, "samples": 4800,
             "components": {"cycle, PDOs and supervision (crest/driver/)": 0.7, "canopen": 0.25, "python-can": 0.05}}
    idle = {"tid": 13, "name": "aurora /dev/pts/0", "cpu_user": 0.004, "cpu_kernel": 0.0, "samples": 4800,
            "components": {"tracker client (crest/tracker/)": 1.0}}
    profile = [{"pid": 11, "command": "crest bench", "role": "master", "cpu_user": 0.304, "cpu_kernel": 0.1,
                "threads": [cycle, idle]}]
    profiled = {**STACK, "profile": profile, "profile_seconds": 48.0, "profile_rate_hz": 100}
    lines = format_table({"stack_profile": profiled}).splitlines()
    run = next(line for line in lines if line.startswith("| Full stack at 500 Hz across processes, profiled"))
    assert "py-spy at 100 samples/s of every thread for 48 s" in run and "0 missed" in run
    assert run.rstrip().endswith("| not the goal's measurement | - |")
    master = next(line for line in lines if line.startswith("| Profile: master (pid 11)"))
    assert ("CPU 40% of one CPU (10% in the kernel); by thread, with where it was: MainThread 40% "
            "(cycle, PDOs and supervision (crest/driver/) 70%, canopen 25%)") in master
    assert "python-can" not in master and "aurora" not in master      # under 10% of samples, under 1% CPU
    refused = format_table({"stack_profile": {"unavailable": "py-spy is not installed"}})
    assert "| Full stack at 500 Hz across processes, profiled | no profile: py-spy is not installed |" in refused


def test_the_recording_rows_name_each_plant_family_and_every_figure_measured():
    recorded = {"family": "rod", "sync_cycles": 22923, "simulated_s": 229.23, "wall_s": 61.4, "cpu_s": 60.2,
                "cycles_per_cpu_s": 380.8, "simulated_time_factor": 3.73}
    table = format_table({"recording": {"rod": recorded}})
    row = next(line for line in table.splitlines() if line.startswith("| Recording in simulated time"))
    assert "rod plant" in row and "22923 SYNC cycles (229 s simulated) in 61.4 s, 60.2 s CPU" in row
    assert "381 cycles per CPU second, 3.7x real time" in row
