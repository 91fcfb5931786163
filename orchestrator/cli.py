"""The ``mechcosim`` command: run scenes, build and validate FMUs, read reports."""

from __future__ import annotations

import argparse
import json
import math
import sys
import tomllib
from pathlib import Path

from orchestrator.errors import RunError, ScenarioError
from orchestrator.interrupt import Interrupted, report_interrupted, signum_of
from orchestrator.run_text import summary_lines


class _OneLineErrors(argparse.ArgumentParser):
    """Bad arguments end like every other bad input: one line on standard error, exit 2
    (argparse's own ends with its usage block first)."""

    def error(self, message: str):  # type: ignore[override]
        self.exit(2, f"error: {self.prog}: {message} (see {self.prog} --help)\n")


def main(argv: list[str] | None = None) -> int:
    """Exit codes: 0 done, 1 a run or check failed, 2 bad input (one line on standard
    error; the traceback only with --debug), 130/143 interrupted by SIGINT/SIGTERM."""
    parser = _OneLineErrors(prog="mechcosim", description=__doc__)
    parser.add_argument("--debug", action="store_true", help="show the full traceback of an error")
    sub = parser.add_subparsers(dest="command", required=True, parser_class=_OneLineErrors)

    p = sub.add_parser("run", help="run a scene and write its results")
    p.add_argument("scene", type=Path, help="scenario file (TOML)")
    p.add_argument(
        "--set",
        action="append",
        default=[],
        metavar="KEY=VALUE",
        help="override a scenario value, e.g. --set master.step='0.5 ms'",
    )
    p.add_argument("--output", type=Path, help="results directory (default: the scene's)")
    p.add_argument("--no-progress", action="store_true", help="no progress bar")
    p.add_argument("--no-plot", action="store_true", help="no PNG of the run")
    p.add_argument(
        "--no-reference",
        action="store_true",
        help="no comparison with the scene's reference (no accuracy in the summary)",
    )
    p.add_argument(
        "--force", action="store_true", help="run even a scene of more than 1e8 macro steps"
    )
    p.add_argument(
        "--in-process",
        action="store_true",
        help="run in this process, not a supervised child: an FMU that crashes then ends "
        "the command without a summary (for a debugger)",
    )
    p.set_defaults(handler=_run)

    p = sub.add_parser("check", help="validate a scenario file without running it")
    p.add_argument("scene", type=Path, nargs="+")
    p.add_argument("--set", action="append", default=[], metavar="KEY=VALUE")
    p.add_argument("--force", action="store_true", help="accept more than 1e8 macro steps")
    p.set_defaults(handler=_check)

    p = sub.add_parser(
        "draw", help="draw a scene's mechanism to scale as entered (its design), before a run"
    )
    p.add_argument("scene", type=Path, help="scenario file (TOML)")
    p.add_argument("--output", type=Path, help="the PNG to write (default: <scene name>.png here)")
    p.add_argument("--set", action="append", default=[], metavar="KEY=VALUE")
    p.set_defaults(handler=_draw)

    p = sub.add_parser("build", help="build FMUs (all if none named) into the cache")
    p.add_argument("names", nargs="*")
    p.add_argument("--force", action="store_true", help="rebuild even if cached")
    p.add_argument("--dest", type=Path, help="cache directory (default: user cache)")
    p.set_defaults(handler=_build)

    p = sub.add_parser(
        "validate", help="validate FMUs: fmpy validation, standalone run, state round trip"
    )
    p.add_argument("names", nargs="*")
    p.set_defaults(handler=_validate)

    p = sub.add_parser(
        "export", help="write a scene as an SSP 1.0 archive (SystemStructure.ssd + its FMUs)"
    )
    p.add_argument("scene", type=Path)
    p.add_argument("out", type=Path, help="the .ssp file to write")
    p.add_argument("--set", action="append", default=[], metavar="KEY=VALUE")
    p.add_argument(
        "--osp",
        type=Path,
        metavar="DIR",
        help="also write libcosim's OspSystemStructure.xml with the FMUs beside it into DIR",
    )
    p.add_argument(
        "--force", action="store_true", help="replace an existing archive (never a scene file)"
    )
    p.set_defaults(handler=_export)

    p = sub.add_parser(
        "crosscheck",
        help="run a scene's exported system in libcosim and FMPy at the master's fixed step "
        "and compare with our Jacobi master (exit 1 unless they agree to 1e-9)",
    )
    p.add_argument("scene", type=Path)
    p.add_argument("--tool", choices=["libcosim", "fmpy"], help="only this tool (default: both)")
    p.add_argument(
        "--via",
        choices=["ssp", "osp"],
        default="ssp",
        help="what libcosim loads: the SSP archive (default) or the OSP-IS file",
    )
    p.add_argument(
        "--stop",
        help="simulated time to compare over, e.g. '2 ms' (default: the scene's stop, "
        "at most 5000 macro steps)",
    )
    p.add_argument("--set", action="append", default=[], metavar="KEY=VALUE")
    p.set_defaults(handler=_crosscheck)

    p = sub.add_parser("precision", help="work–precision report: error against wall time")
    p.add_argument("scene", type=Path)
    p.add_argument("--output", type=Path, help="directory (default runs/<scene>_work_precision)")
    p.add_argument("--workers", type=int, help="local processes (default: one per core)")
    p.add_argument("--dask", metavar="ADDRESS", help="run the sweep on this Dask scheduler")
    p.add_argument(
        "--tolerances",
        type=_floats,
        help="tolerances of the tolerance-driven masters and the regime-aware single pass, "
        "comma-separated (default 1e-1,1e-2,...,1e-5)",
    )
    p.add_argument(
        "--step-factors",
        type=_floats,
        help="fixed-step macro steps as multiples of the scene's (default 8,...,0.25)",
    )
    p.add_argument(
        "--start-hold-tolerances",
        type=_floats,
        help="also run the regime-aware master with inputs held at the step start "
        "(input_hold = 'start', the first-order error test) at these tolerances",
    )
    p.add_argument(
        "--monolithic-tolerances",
        type=_floats,
        help="tolerances of the scene's monolithic model, where its family has one "
        "(default 1e-3,3e-4,...,1e-10)",
    )
    p.add_argument(
        "--repeats",
        type=int,
        default=1,
        help="run every master setting this many times and keep its least wall time (default 1)",
    )
    p.add_argument("--set", action="append", default=[], metavar="KEY=VALUE")
    p.set_defaults(handler=_precision)

    p = sub.add_parser("sweep", help="run a scene's [sweep]: one run per value, CSV/PNG/table")
    p.add_argument("scene", type=Path)
    p.add_argument("--set", action="append", default=[], metavar="KEY=VALUE")
    p.add_argument("--output", type=Path, help="directory (default runs/<scene>/sweep)")
    p.add_argument("--workers", type=int, help="local processes (default: one per core)")
    p.add_argument("--dask", metavar="ADDRESS", help="run the sweep on this Dask scheduler")
    p.add_argument("--run-plots", action="store_true", help="draw each run's plot too")
    p.set_defaults(handler=_sweep)

    p = sub.add_parser(
        "study", help="run a scene's [study]: tolerances varied at once, statistics of the results"
    )
    p.add_argument("scene", type=Path)
    p.add_argument("--samples", type=int, help="number of samples (default: the scene's)")
    p.add_argument("--set", action="append", default=[], metavar="KEY=VALUE")
    p.add_argument("--output", type=Path, help="directory (default runs/<scene>/study)")
    p.add_argument("--workers", type=int, help="local processes (default: one per core)")
    p.add_argument("--dask", metavar="ADDRESS", help="run the samples on this Dask scheduler")
    p.add_argument(
        "--resume", action="store_true", help="keep the samples in samples.csv, run the rest"
    )
    p.add_argument("--no-progress", action="store_true", help="no progress bar")
    p.add_argument(
        "--keep-going",
        action="store_true",
        help="run every sample even when the first ones all fail with the same error",
    )
    p.set_defaults(handler=_study)

    p = sub.add_parser("stability", help="run the stability suite (scenarios/stability/)")
    p.add_argument("--output", type=Path, default=Path("runs") / "stability")
    p.add_argument("--workers", type=int, help="local processes (default: one per core)")
    p.add_argument("--dask", metavar="ADDRESS", help="run the cases on this Dask scheduler")
    p.set_defaults(handler=_stability)

    p = sub.add_parser("bench", help="run a benchmark (prints ratios against its baseline)")
    p.add_argument(
        "name", choices=["overhead", "m739", "speed", "supervision", "animate", "study", "answer"]
    )
    p.set_defaults(handler=_bench)

    p = sub.add_parser(
        "report",
        help="print what a run printed as it ended (completed, failed, interrupted or "
        "crashed), or how far a run in progress or killed got",
    )
    p.add_argument("run_dir", type=Path, help="the run's results directory (its summary.json)")
    p.add_argument("--json", action="store_true", help="the summary as JSON instead")
    p.set_defaults(handler=_report)

    p = sub.add_parser(
        "animate",
        help="animate a run: its mechanism to scale, moving with the recorded angles (GIF, MP4)",
    )
    p.add_argument("run_dir", type=Path, help="the run's results directory")
    p.add_argument("--output", type=Path, help="GIF file (default: RUN_DIR/<scene>.gif)")
    p.add_argument("--start", help="simulated time to begin at, e.g. '1 ms' (default: 0)")
    p.add_argument("--stop", help="simulated time to end at, e.g. '5 ms' (default: the end)")
    p.add_argument("--fps", type=float, default=25.0, help="frames per second (default 25)")
    p.add_argument("--size", default="880x440", help="WIDTHxHEIGHT in pixels (default 880x440)")
    pace = p.add_mutually_exclusive_group()
    pace.add_argument("--slowdown", type=float, help="slow-motion factor (default: the family's)")
    pace.add_argument("--duration", help="or: how long the window plays, e.g. '10 s'")
    p.add_argument("--no-mp4", action="store_true", help="no MP4, even where ffmpeg is")
    p.add_argument("--no-progress", action="store_true", help="no progress bar")
    p.set_defaults(handler=_animate)

    args = parser.parse_args(argv)
    return _handled(args.handler, args)


def _handled(handler, args: argparse.Namespace) -> int:  # noqa: ANN001 - a command handler
    """Run a command's handler; an error becomes one line and an exit code."""
    from fmus.build import BuildError  # before the try: its except clauses name it

    try:
        return handler(args)
    except (KeyboardInterrupt, Interrupted) as exc:
        if args.debug:
            raise
        return report_interrupted(signum_of(exc))
    except (ScenarioError, RunError, BuildError, OSError, UnicodeError) as exc:
        # bad input: a scene, a path, a cache, a results directory
        if args.debug:
            raise
        print(f"error: {_one_line(exc)}", file=sys.stderr)
        return 2
    except Exception as exc:  # noqa: BLE001 - the command line never shows a bare traceback
        if args.debug:
            raise
        print(
            f"error: {type(exc).__name__}: {_one_line(exc)} (--debug shows the traceback)",
            file=sys.stderr,
        )
        return 1


def _one_line(exc: BaseException) -> str:
    """The first line of an error's message (FMU failures may carry a traceback after it)."""
    if isinstance(exc, OSError) and exc.strerror:
        where = f"{exc.filename}: " if exc.filename else ""
        return f"{where}{exc.strerror}"
    text = str(exc).strip()
    return text.splitlines()[0] if text else type(exc).__name__


def _overrides(pairs: list[str]) -> dict[str, object]:
    out: dict[str, object] = {}
    for pair in pairs:
        key, sep, text = pair.partition("=")
        if not sep:
            raise ScenarioError("--set", pair, "expected KEY=VALUE")
        try:  # a TOML value (number, quoted string, array) ...
            out[key] = tomllib.loads(f"v = {text}")["v"]
        except tomllib.TOMLDecodeError:  # ... or a bare string such as 0.5 ms
            out[key] = text
    return out


def _floats(text: str) -> tuple[float, ...]:
    try:
        values = tuple(float(v) for v in text.split(","))
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"expected comma-separated numbers, got {text!r}"
        ) from None
    if not values or min(values) <= 0.0:
        raise argparse.ArgumentTypeError(f"expected positive numbers, got {text!r}")
    return values


def _run(args: argparse.Namespace) -> int:
    from orchestrator.interrupt import catching_signals
    from orchestrator.supervisor import can_supervise, supervised

    args.started_up = _since_process_start()  # here: a supervised run's child starts anew
    # From here on SIGINT/SIGTERM only set a flag: the run stops at a step boundary.
    with catching_signals() as guard:
        if args.in_process or not can_supervise():
            code = _run_guarded(args)
        else:
            # The run in a child process, under this guard; a crash there is reported here.
            def child(args: argparse.Namespace) -> int:
                code = _run_guarded(args)
                return 128 + guard.signum if guard.signum is not None else code

            return supervised(lambda: _handled(child, args), guard)
    if guard.signum is not None:
        return 128 + guard.signum
    return code


def _run_guarded(args: argparse.Namespace) -> int:
    import time

    started_up = getattr(args, "started_up", None) or _since_process_start()
    phases: dict[str, float] = {"start-up (interpreter, command line)": started_up}
    start = time.perf_counter()
    from orchestrator.cache import check_cache_dir
    from orchestrator.run import run_scene

    phases["imports"] = time.perf_counter() - start
    start = time.perf_counter()
    check_cache_dir()
    scene = _load(args.scene, _overrides(args.set), args.force)
    phases["scene load"] = time.perf_counter() - start
    result = run_scene(
        scene,
        output_dir=args.output,
        show_progress=not args.no_progress,
        plots=not args.no_plot,
        compare_reference=not args.no_reference,
    )
    phases.update(result.phases)
    summary = {
        "scene": scene.name,
        "status": result.status,
        "message": result.message,
        "time_reached": result.time_reached,
        "headline": result.headline,
        "accuracy": result.accuracy,
        "notes": result.notes,
        "stats": result.stats.as_dict(),
    }
    print("\n".join(summary_lines(summary, result.output_dir)))
    if args.debug:
        sys.stdout.flush()
        _print_phases(phases)
    return 0 if result.status == "completed" else 1


def _since_process_start() -> float:
    """Wall time [s] since this process started (Linux: /proc; elsewhere NaN)."""
    import os

    try:
        with open("/proc/self/stat") as f:
            ticks = int(f.read().rpartition(")")[2].split()[19])
        with open("/proc/uptime") as f:
            uptime = float(f.read().split()[0])
        return uptime - ticks / os.sysconf("SC_CLK_TCK")
    except (OSError, ValueError, IndexError):
        return math.nan


def _print_phases(phases: dict[str, float]) -> None:
    """One line a phase, its wall time, on standard error (``--debug``)."""
    width = max(len(name) for name in phases)
    print("phases (wall time):", file=sys.stderr)
    for name, seconds in phases.items():
        print(f"  {name:<{width}}  {seconds:8.3f} s", file=sys.stderr)
    total = sum(v for v in phases.values() if not math.isnan(v))
    print(f"  {'total':<{width}}  {total:8.3f} s", file=sys.stderr)


def _load(path: Path, overrides: dict, force: bool):  # noqa: ANN202 - a Scene
    """A scene from its TOML file, or a system from an SSP archive (``.ssp``)."""
    if Path(path).suffix.lower() == ".ssp":
        from orchestrator.ssp_import import load_ssp

        return load_ssp(path, overrides, force=force)
    from orchestrator.scenario import load_scene

    return load_scene(path, overrides, force=force)


def _check(args: argparse.Namespace) -> int:
    from orchestrator.cache import check_cache_dir

    check_cache_dir()
    for path in args.scene:
        scene = _load(path, _overrides(args.set), args.force)
        counts = f"{len(scene.fmus)} FMUs, {len(scene.connections)} connections"
        print(f"{path}: ok ({scene.name}, {counts})")
    return 0


def _draw(args: argparse.Namespace) -> int:
    from orchestrator.scenes import DRAWINGS

    scene = _load(args.scene, _overrides(args.set), False)
    name = getattr(scene, "family", None)
    if name is None or name not in DRAWINGS:
        raise ScenarioError(
            args.scene,
            "report.family",
            f"{name!r} has no drawing; drawn are the families {sorted(DRAWINGS)}",
        )
    out = args.output or Path(f"{scene.name}.png")
    DRAWINGS[name](scene, out)
    print(f"{args.scene}: drawn to {out}")
    return 0


def _build(args: argparse.Namespace) -> int:
    from fmus.build import build_fmu
    from fmus.registry import FMU_RECORDS
    from orchestrator.cache import check_cache_dir

    check_cache_dir(args.dest)
    for name in args.names or sorted(FMU_RECORDS):
        print(build_fmu(name, args.dest, force=args.force))
    return 0


def _validate(args: argparse.Namespace) -> int:
    from fmus.registry import FMU_RECORDS
    from orchestrator.fmu_checks import check_fmu

    failures = 0
    for name in args.names or sorted(FMU_RECORDS):
        problems = check_fmu(name)
        print(f"{name}: {'ok' if not problems else 'FAILED'}")
        for problem in problems:
            print(f"  - {problem}")
        failures += bool(problems)
    return 1 if failures else 0


def _export(args: argparse.Namespace) -> int:
    from orchestrator.osp_export import export_osp
    from orchestrator.scenario import load_scene
    from orchestrator.ssp_export import export_ssp

    if args.osp is not None and args.osp.exists() and not args.osp.is_dir():
        print(f"error: --osp {args.osp}: is a file; expected a directory", file=sys.stderr)
        return 2
    from orchestrator.export_target import check_export_target, check_not_read

    check_export_target(args.scene, args.out, args.force)
    scene = load_scene(args.scene, _overrides(args.set))
    check_not_read(scene, args.out)
    if args.osp is not None:  # it writes <instance>.fmu there
        for name, spec in scene.fmus.items():
            check_not_read(scene, args.osp / f"{name}.fmu", "--osp", copy_of=spec.path)
    if args.osp is not None:  # first: it carries input signals, which SSP refuses
        print(f"{export_osp(scene, args.osp)}: the FMUs beside it")
    out = export_ssp(scene, args.out)
    print(f"{out}: {len(scene.fmus)} components, {len(scene.connections)} connections")
    return 0


def _crosscheck(args: argparse.Namespace) -> int:
    from orchestrator.studies import crosscheck as cc

    tools = (args.tool,) if args.tool else cc.TOOLS
    check = cc.crosscheck(args.scene, _overrides(args.set), args.stop, tools, args.via)
    scene = check.scene
    how = "as asked" if args.stop else f"the scene's stop, at most {cc.DEFAULT_MAX_STEPS} steps"
    print(
        f"{scene.name}: {check.steps} fixed steps of {scene.master.step!r} s to "
        f"{scene.stop:.9g} s ({how}); required agreement {cc.REQUIRED:g}"
    )
    if not math.isnan(check.ours_wall_time):
        print(f"  mechcosim Jacobi: {check.ours_wall_time:.2f} s")
    for o in check.outcomes:
        if o.cannot_run is not None:
            print(f"  {o.tool} cannot run {scene.name}: {o.cannot_run}")
            continue
        name, worst = o.agreement.worst
        print(
            f"  {o.tool} ({o.run.via}): agreement {worst:.3e} (worst {name}) over "
            f"{o.agreement.points} points, {len(o.agreement.per_signal)} signals, "
            f"{o.run.wall_time:.2f} s: {'ok' if o.ok else 'NOT MET'}"
        )
        for quantity, why in o.run.not_compared.items():
            print(f"    not compared: {quantity} ({why})")
    print("  agreement: max over signals of max_k |ours - theirs| / max_k max(|ours|, |theirs|)")
    return 0 if check.ok else 1


def _precision(args: argparse.Namespace) -> int:
    from orchestrator.studies.monolithic_curve import CURVE_TOLERANCES
    from orchestrator.studies.work_precision import (
        STEP_FACTORS,
        TOLERANCES,
        observed_order,
        work_precision,
    )

    if args.repeats < 1:
        raise ScenarioError("--repeats", "", f"expected a whole number >= 1, got {args.repeats}")
    rows = work_precision(
        args.scene,
        args.output,
        step_factors=args.step_factors or STEP_FACTORS,
        tolerances=args.tolerances or TOLERANCES,
        start_hold_tolerances=args.start_hold_tolerances or (),
        workers=args.workers,
        dask_address=args.dask,
        overrides=_overrides(args.set),
        repeats=args.repeats,
        monolithic_tolerances=args.monolithic_tolerances or CURVE_TOLERANCES,
    )
    for master in dict.fromkeys(r.master for r in rows):
        line = f"  {master:22s} observed order {observed_order(rows, master):.2f}"
        ratios = [r.monolithic_ratio for r in rows if r.master == master]
        ratios = [x for x in ratios if not math.isnan(x)]  # those in the error window
        if ratios:
            word = rows[0].headline.word  # what the family's headline quantity counts
            line += f", x monolithic at the same {word} error {min(ratios):.2f}..{max(ratios):.2f}"
        print(line)
    out = Path(rows[0].result.job.output_dir).parent if rows else args.output
    print(f"report in {out}/work_precision.md (.csv, .png)")
    return 0


def _sweep(args: argparse.Namespace) -> int:
    from orchestrator.studies.parameter_sweep import run_sweep

    result = run_sweep(
        args.scene,
        args.output,
        args.workers,
        args.dask,
        _overrides(args.set) or None,
        run_plots=args.run_plots,
    )
    print((result.output_dir / "sweep.md").read_text())
    print(f"results in {result.output_dir} (sweep.csv, sweep.png, sweep.md)")
    return 0 if all(r["status"] == "completed" for r in result.rows) else 1


def _study(args: argparse.Namespace) -> int:
    from orchestrator.studies.study_report import limit_rows
    from orchestrator.studies.study_statistics import summarize
    from orchestrator.studies.tolerance_study import OK, run_study

    result = run_study(
        args.scene,
        samples=args.samples,
        workers=args.workers,
        dask_address=args.dask,
        resume=args.resume,
        overrides=_overrides(args.set) or None,
        output_dir=args.output,
        show_progress=not args.no_progress,
        keep_going=args.keep_going,
    )
    for note in result.notes:
        print(f"note: {note}", file=sys.stderr)
    if result.stopped:
        print(f"error: study {result.scene.name}: {result.stopped}", file=sys.stderr)
    ok = sum(s.status == OK for s in result.samples)
    print(
        f"study {result.scene.name}: {len(result.samples)} of {result.requested} samples, "
        f"{ok} with every quantity; {result.ran} run in {result.wall_time:.1f} s"
    )
    for s in result.samples:
        if s.status != OK:
            print(f"  sample {s.index}: {s.status}: {s.reason}")
    for q in result.spec.quantities:
        summary = summarize(result.values(q), seed=result.spec.seed)
        pct = ", ".join(f"p{p} {e.value:.5g}" for p, e in summary.percentiles.items())
        print(f"  {q}: mean {summary.mean.value:.6g}, sd {summary.sd.value:.4g}; {pct}")
    for q, words, v, _ in limit_rows(result):
        print(f"  {q} {words}: {v.k} of {v.n} violate, < {100 * v.upper:.3g} % at 95 %")
    print(f"results in {result.output_dir} (samples.csv, study.md, study.png)")
    if result.interrupted is not None:
        return 128 + result.interrupted
    return 0 if ok and not result.stopped else 1


def _stability(args: argparse.Namespace) -> int:
    from orchestrator.studies.stability import run_suite

    rows = run_suite(out_dir=args.output, workers=args.workers, dask_address=args.dask)
    print((args.output / "stability.md").read_text())
    unstable = [r for r in rows if r.master == "regime-aware" and not r.stable and not r.diagnosis]
    return 1 if unstable else 0


def _bench(args: argparse.Namespace) -> int:
    from orchestrator.studies.benchmarks import BENCHMARKS

    BENCHMARKS[args.name]()
    return 0


def _animate(args: argparse.Namespace) -> int:
    from orchestrator.animate import AnimationOptions, animate_run
    from orchestrator.progress import ProgressBar
    from orchestrator.units import to_si

    def seconds(option: str, text: str | None) -> float | None:
        if text is None:
            return None
        try:
            return to_si(text, "s")
        except ValueError as exc:
            raise ScenarioError(option, "", f"{exc}; expected a time such as '5 ms'") from None

    w, sep, h = args.size.lower().partition("x")
    if not (sep and w.isdigit() and h.isdigit() and int(w) >= 64 and int(h) >= 64):
        raise ScenarioError("--size", "", f"{args.size!r}: expected WIDTHxHEIGHT in pixels, "
                            "each at least 64, e.g. 880x440")  # fmt: skip
    options = AnimationOptions(
        start=seconds("--start", args.start),
        stop=seconds("--stop", args.stop),
        fps=args.fps,
        size=(int(w), int(h)),
        slowdown=args.slowdown,
        duration=seconds("--duration", args.duration),
        mp4=not args.no_mp4,
    )

    bars: list[ProgressBar] = []

    def progress(total: int):  # noqa: ANN202 - a per-frame tick
        bars.append(ProgressBar(total=total, unit="frame", delay=1.0, leave=False,
                                disable=args.no_progress))  # fmt: skip
        return lambda: bars[0].update(1)

    try:
        made = animate_run(args.run_dir, args.output, options, progress)
    finally:
        for bar in bars:
            bar.close()
    for note in made.notes:
        print(f"note: {note}")
    what = f"{made.gif}" + (f" and {made.mp4}" if made.mp4 else " (no ffmpeg: no MP4)")
    print(
        f"{args.run_dir}: animated to {what}: {made.frames} frames of {made.size[0]}x"
        f"{made.size[1]}, {made.start * 1e3:.6g} .. {made.stop * 1e3:.6g} ms simulated at "
        f"{made.slowdown:g}x slower, {made.fps:g} frames/s; {made.wall_time:.1f} s"
    )
    return 0


def _report(args: argparse.Namespace) -> int:
    from orchestrator.run_state import run_summary

    try:
        summary = run_summary(args.run_dir)
    except RunError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    if args.json:
        print(json.dumps(summary, indent=2))
    else:
        print("\n".join(summary_lines(summary, args.run_dir)))
    return 0


if __name__ == "__main__":
    # ``python -m orchestrator.cli`` runs the command as ``python -m orchestrator`` does,
    # through orchestrator.entry (its signal handling while the modules load and after).
    import runpy

    runpy.run_module("orchestrator", run_name="__main__")
