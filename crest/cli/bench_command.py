"""`crest bench --json OUT.json`: measure the stack against its limits, on this machine."""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from control.benchmark import controller_cycle_times
from crest.bench import model_bench, plant_bench, recording_bench, stack_bench, view_bench
from crest.cli.common_options import check_output
from crest.bench.machine_info import machine_info
from crest.bench.machine_stalls import PROBE_PERIOD_S, PROBE_PRIORITY, STALL_THRESHOLD_S, machine_floor
from crest.bench.process_profile import ProfilerUnavailable
from crest.gap.benchmark import GOAL_S, diagnosis_benchmarks
from model import CatheterParams

GAP_CASES = {"synthetic": "Gap diagnosis, synthetic 10-min 100 Hz log (easy case)",
             "virtual_testbed": "Gap diagnosis, 10-min 100 Hz virtual-testbed log, drawn plant",
             "real": "Gap diagnosis, longest real log"}
STACK_REALTIME_PRIORITY = 20    # SCHED_FIFO priority of the full stack's threads (crest.driver.realtime_scheduling)
SECTIONS = ("model", "dynamic", "scaling", "move", "controllers", "rod_plant", "recording", "full_stack",
            "stack_profile", "gap", "view")


def add_parser(sub) -> None:
    parser = sub.add_parser("bench", help="benchmark the model, controllers, rod plant, recording in simulated time, "
                                          "full stack and gap diagnosis")
    parser.add_argument("--json", dest="json_path", default="bench.json", help="where to write the results")
    parser.add_argument("--only", nargs="+", choices=SECTIONS, default=list(SECTIONS),
                        help="run only these sections")
    parser.add_argument("--stack-seconds", type=float, default=60.0,
                        help="duration of each full-stack run (default 60): 500 Hz and 1 kHz SYNC with the testbed "
                             "in a process of its own, and 500 Hz with it in the master's process, each with the "
                             "threads at --realtime-priority; 500 Hz across processes also under the normal scheduler; "
                             "first, as long, the machine's own stalls seen by an idle real-time process")
    parser.add_argument("--realtime-priority", type=int, default=STACK_REALTIME_PRIORITY, choices=range(1, 100),
                        metavar="1..99",
                        help=f"full stack: the SCHED_FIFO priority of both processes' threads (default "
                             f"{STACK_REALTIME_PRIORITY}); where the system does not grant it, the results say so")
    parser.add_argument("--view-seconds", type=float, default=20.0,
                        help="duration of each control-loop run without and with the live view (default 20)")
    parser.add_argument("--gap-seed", type=int, default=0,
                        help="gap section: seed of the virtual-testbed plant (its log is recorded once and cached)")
    parser.add_argument("--gap-cases", nargs="+", choices=GAP_CASES, default=list(GAP_CASES),
                        help="gap section: only these logs (the synthetic one is recorded anew each time, about "
                             "14 minutes)")
    parser.add_argument("--real-data", type=Path, default=None,
                        help="gap section: the continuum_nathan folder (default ../shared/data/continuum_nathan "
                             "beside the repository); the real-log case is skipped where it is absent")
    parser.add_argument("--view-realtime", action="store_true",
                        help="view section: pace the loop in real time instead of running it back to back")
    parser.set_defaults(handler=run)


def run(args: argparse.Namespace) -> int:
    path = Path(args.json_path)
    check_output(path)                                             # refused now, not after the benchmarks
    params = CatheterParams.from_toml()
    results: dict = {"machine": machine_info()}
    steps = {
        "model": lambda: model_bench.model_step(params),
        "dynamic": lambda: model_bench.dynamic_model_step(params),
        "scaling": lambda: model_bench.scaling_in_n(params),
        "move": lambda: model_bench.quasi_static_move(params),
        "controllers": lambda: controller_cycle_times(params),
        "rod_plant": lambda: plant_bench.rod_plant(),
        "recording": lambda: recording_bench.recording(),
        "full_stack": lambda: {
            "machine_floor": machine_floor_result(args.stack_seconds, args.realtime_priority),
            **{f"{rate:.0f}_hz_testbed_process": stack_bench.full_stack(
                rate, args.stack_seconds, testbed_process=True, realtime_priority=args.realtime_priority)
               for rate in (500.0, 1000.0)},
            "500_hz_testbed_process_normal_scheduler": stack_bench.full_stack(500.0, args.stack_seconds,
                                                                              testbed_process=True),
            "500_hz_one_process": stack_bench.full_stack(500.0, args.stack_seconds, testbed_process=False,
                                                         realtime_priority=args.realtime_priority)},
        "stack_profile": lambda: stack_profile_result(args.stack_seconds, args.realtime_priority,
                                                      path.parent / f"{path.stem}_profile"),
        "gap": lambda: diagnosis_benchmarks(args.gap_seed, args.real_data, cases=args.gap_cases,
                                            progress=lambda message: print(f"crest bench: {message}",
                                                                           file=sys.stderr, flush=True)),
        "view": lambda: view_bench.control_loop_with_and_without_view(
            args.view_seconds, realtime=args.view_realtime),
    }
    for name in args.only:
        if name not in steps:
            continue
        print(f"crest bench: {name} ...", file=sys.stderr, flush=True)
        results[name] = steps[name]()
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(results, indent=2))
    print(format_table(results))
    print(f"results written to {path}")
    return 0


def machine_floor_result(duration_s: float, stack_priority: int) -> dict:
    """The machine's own stalls (crest.bench.machine_stalls), probed on every CPU at once above the
    stack's priority: their union, and each CPU's."""
    floor = machine_floor(duration_s, min(99, max(PROBE_PRIORITY, stack_priority + 1)))
    report = floor.any_cpu
    return {"duration_s": duration_s, "period_s": PROBE_PERIOD_S, "probe": report.scheduling,
            "wakeups": report.wakeups, "stalls": len(report.stalls), "stall_threshold_s": STALL_THRESHOLD_S,
            "stalls_over_1_ms": report.longer_than(0.001), "longest_ms": report.longest_ms,
            "stalls_over_1_ms_per_cpu": {str(cpu): r.longer_than(0.001) for cpu, r in floor.per_cpu.items()},
            "stalls_over_1_ms_on_every_cpu": floor.on_every_cpu(0.001)}


def stack_profile_result(duration_s: float, priority: int, folder: Path) -> dict:
    """The 500 Hz full stack across processes once more, each process profiled (stack_bench,
    crest.bench.process_profile), py-spy's raw stacks in `folder`. Where py-spy cannot read the
    processes, the reason instead."""
    try:
        return stack_bench.full_stack(500.0, duration_s, testbed_process=True, realtime_priority=priority,
                                      profile_folder=folder)
    except ProfilerUnavailable as error:
        return {"unavailable": str(error)}


def _steal_text(hypervisor: dict) -> str:
    """The hypervisor's steal time during one stack run (crest.bench.steal_time), or nothing."""
    if not hypervisor["steal_ms_per_cpu"]:
        return ""
    per_cpu = ", ".join(f"CPU {cpu} {ms:g} ms" for cpu, ms in hypervisor["steal_ms_per_cpu"].items())
    return f"; taken by the hypervisor during the run: {per_cpu} (to {hypervisor['resolution_ms']:g} ms)"


def _profile_rows(r: dict | None) -> list[tuple]:
    """The profiled run's rows: its timing, then each process's CPU by thread, with where each thread is."""
    if r is None:
        return []
    label = "Full stack at 500 Hz across processes, profiled"
    if "unavailable" in r:
        return [(label, f"no profile: {r['unavailable']}", "-", None)]
    rows = [(f"{label} ({r['duration_s']:.0f} s; py-spy at {r['profile_rate_hz']} samples/s of every thread for "
             f"{r['profile_seconds']:.0f} s, stopping each process to read it)",
             f"{r['achieved_rate_hz']:.0f} Hz, jitter p99 {r['jitter_p99_ms']:.2f} ms, {r['missed_cycles']} missed"
             + _steal_text(r["hypervisor"]), "not the goal's measurement", None)]
    for process in r["profile"]:
        threads = []
        for thread in process["threads"]:
            cpu = thread["cpu_user"] + thread["cpu_kernel"]
            if cpu >= 0.01:
                where = ", ".join(f"{name} {100 * share:.0f}%" for name, share in thread["components"].items()
                                  if share >= 0.1)
                threads.append(f"{thread['name']} {100 * cpu:.0f}% ({where or 'not sampled'})")
        rows.append((f"Profile: {process['role']} (pid {process['pid']})",
                     f"CPU {100 * (process['cpu_user'] + process['cpu_kernel']):.0f}% of one CPU "
                     f"({100 * process['cpu_kernel']:.0f}% in the kernel); by thread, with where it was: "
                     + ("; ".join(threads) or "none used 1%"), "-", None))
    return rows


def format_table(results: dict) -> str:
    rows = []
    if "model" in results:
        r = results["model"]
        rows.append(("Model step, N=20", f"{r['step_rate_hz']:.0f} steps/s, {r['real_time_factor']:.0f}x real time",
                     f">= {r['goal_real_time_factor']:.0f}x", r["real_time_factor"] >= r["goal_real_time_factor"]))
    if "dynamic" in results:
        r = results["dynamic"]
        rows.append((f"Dynamic model step, N=20 (backward Euler, <= {1e3 * r['max_time_step_s']:g} ms steps)",
                     f"{r['step_rate_hz']:.0f} steps/s, {r['real_time_factor']:.0f}x real time",
                     f">= {r['goal_real_time_factor']:.0f}x", r["real_time_factor"] >= r["goal_real_time_factor"]))
        errors = ", ".join(f"{name} {e:.3f} mm" for name, e in r["time_step_rms_error_mm"].items())
        rows.append((f"Dynamic model, {1e3 * r['max_time_step_s']:g} ms steps vs {1e3 * r['reference_time_step_s']:g} ms, "
                     "tip RMS", errors,
                     "< tracker noise", None))
    if "scaling" in results:
        r = results["scaling"]
        rows.append(("Cost exponent in N (10..320)", f"{r['cost_exponent']:.2f}", f"<= {r['goal_cost_exponent']}",
                     r["cost_exponent"] <= r["goal_cost_exponent"]))
    if "move" in results:
        rows.append(("move_to 0 -> 180 deg", f"{results['move']['wall_ms']:.1f} ms", "-", None))
    for name, r in results.get("controllers", {}).items():
        rows.append((f"Controller {name}, per cycle", f"median {r['median_us']:.0f} us, p99 {r['p99_us']:.0f} us",
                     "well inside 10 ms", r["p99_us"] < 5000))
    for r in results.get("rod_plant", {}).values():
        rows.append((f"Rod plant step, M={r['grid_nodes']} nodes", f"{r['step_rate_hz']:.0f} steps/s, "
                     f"{r['real_time_factor_at_100_hz']:.1f}x real time at 100 Hz "
                     f"({r['step_rate_per_cpu_s']:.0f} steps per CPU second)",
                     f">= {r['goal_step_rate_hz']:.0f} steps/s", r["step_rate_hz"] >= r["goal_step_rate_hz"]))
    for r in results.get("recording", {}).values():
        rows.append((f"Recording in simulated time, the short excitation (what a blind case records two or three "
                     f"times), {r['family']} plant", f"{r['sync_cycles']} SYNC cycles ({r['simulated_s']:.0f} s simulated) in "
                     f"{r['wall_s']:.1f} s, {r['cpu_s']:.1f} s CPU: {r['cycles_per_cpu_s']:.0f} cycles per CPU "
                     f"second, {r['simulated_time_factor']:.1f}x real time", "-", None))
    stacks = dict(results.get("full_stack", {}))
    floor = stacks.pop("machine_floor", None)
    if floor is not None:
        per_cpu = ", ".join(f"CPU {cpu}: {n}" for cpu, n in floor["stalls_over_1_ms_per_cpu"].items())
        rows.append((f"Machine floor: an idle process on each CPU at {floor['probe']} waking every "
                     f"{1e3 * floor['period_s']:g} ms for {floor['duration_s']:.0f} s, just before the full stack",
                     f"{floor['stalls_over_1_ms']} stalls over 1 ms on any CPU (a missed cycle at 500 Hz; "
                     f"{per_cpu}; {floor['stalls_over_1_ms_on_every_cpu']} on every CPU at once), "
                     f"{floor['stalls']} over {1e3 * floor['stall_threshold_s']:g} ms, longest "
                     f"{floor['longest_ms']:.1f} ms",
                     "-", None))
    for key, r in stacks.items():
        rows.append((f"Full stack at {r['sync_rate_hz_nominal']:.0f} Hz SYNC, {r['duration_s']:.0f} s, testbed in "
                     f"{r['testbed']}; master: {r['master_scheduling']}, testbed: {r['testbed_scheduling']}; "
                     f"{r['controller']} commands computed "
                     + ("ahead in a process of their own" if r["commands_in_own_process"] else "in the master"),
                     f"{r['achieved_rate_hz']:.0f} Hz, jitter p50 {r['jitter_p50_ms']:.2f} / p99 "
                     f"{r['jitter_p99_ms']:.2f} ms, {r['missed_cycles']} missed ({r['missed_woke_late']} woke late, "
                     f"{r['missed_overran']} after an overrun), bus load "
                     f"{100 * r['bus_load_mean']:.0f}% of {r['bus_bitrate_bit_s'] / 1e6:g} Mbit/s"
                     + (f"; {r['cycles_held_for_a_command']} cycles held for a command not yet computed"
                        if r["cycles_held_for_a_command"] else "")
                     + (f"; {r['cycles_without_every_answer']} cycles without every drive's answer in time"
                        if r["cycles_without_every_answer"] is not None else "")
                     + "; answers {p50_ms:.2f} / {p99_ms:.2f} / {p99_9_ms:.2f} / {longest_ms:.2f} ms after the SYNC "
                       "(p50 / p99 / p99.9 / longest)".format(**r["answer_latency"])
                     + _steal_text(r["hypervisor"])
                     + (f"; stopped: {r['stopped']}" if r["stopped"] else ""),
                     "rate held, 0 missed (SYNC late or an answer late), p99 <= 1 ms",
                     not r["stopped"] and r["missed_cycles"] == 0 and r["cycles_without_every_answer"] == 0
                     and r["jitter_p99_ms"] <= 1.0))
    rows += _profile_rows(results.get("stack_profile"))
    notes = []
    for key, r in results.get("gap", {}).items():
        label = GAP_CASES[key]
        if "skipped" in r:
            rows.append((label, r["skipped"], f"<= {GOAL_S:.0f} s", None))
            continue
        stages = ", ".join(f"{name} {r['stages_s'][name]:.0f}" for name in ("baseline", "candidates", "pairs", "where")
                           if name in r["stages_s"])
        newton = r["newton_iterations_per_sample"]
        rows.append((label, f"{r['seconds']:.0f} s ({stages} s); {newton['train']['per_sample']:.1f} Newton "
                            f"iterations per sample (training), {newton['holdout']['per_sample']:.1f} (held-out); "
                            f"verdict {'+'.join(r['effects']) or r['verdict']}",
                     f"<= {r['goal_s']:.0f} s", r["met"]))
        notes.append(f"{label}: {r['log']}")
    if "view" in results:
        r = results["view"]
        for key, label in (("without_view", "no view"), ("with_view_no_client", "live view, no page open"),
                           ("with_view", f"live view, client: {r['client']}")):
            c = r[key]
            rows.append((f"Control loop cycle ({r['clock']}), {label}",
                         f"median {c['median_ms']:.2f} ms, p99 {c['p99_ms']:.2f} ms, {c['late_cycles']} of "
                         f"{c['cycles']} over 1.5 SYNC periods", f"SYNC period {c['sync_period_ms']:g} ms", None))
            if "page_answer_ms" in c:
                a = c["page_answer_ms"]
                rows.append((f"Live view page's answer to a script during that run ({a['count']} timings)",
                             f"median {a['median']:.0f} ms, longest {a['longest']:.0f} ms",
                             "well under a second (an E-STOP click waits as long)", None))
    lines = ["| measure | result | goal | met |", "|---|---|---|---|"]
    for name, value, goal, met in rows:
        lines.append(f"| {name} | {value} | {goal} | {'-' if met is None else ('yes' if met else 'NO')} |")
    return "\n".join(lines + ([""] + notes if notes else []))
