"""The ``mechcosim`` command: run scenes, build and validate FMUs, read reports."""

from __future__ import annotations

import argparse
import json
import sys
import tomllib
from pathlib import Path

from orchestrator.errors import RunError, ScenarioError


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="mechcosim", description=__doc__)
    sub = parser.add_subparsers(dest="command", required=True)

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
    p.set_defaults(handler=_run)

    p = sub.add_parser("check", help="validate a scenario file without running it")
    p.add_argument("scene", type=Path, nargs="+")
    p.set_defaults(handler=_check)

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
        "crosscheck", help="run a scene in libcosim too and compare with our Jacobi master"
    )
    p.add_argument("scene", type=Path)
    p.set_defaults(handler=_crosscheck)

    p = sub.add_parser("precision", help="work–precision report: error against wall time")
    p.add_argument("scene", type=Path)
    p.add_argument("--output", type=Path, help="directory (default runs/<scene>_work_precision)")
    p.add_argument("--workers", type=int, help="local processes (default: one per core)")
    p.add_argument("--dask", metavar="ADDRESS", help="run the sweep on this Dask scheduler")
    p.add_argument(
        "--tolerances",
        type=_floats,
        help="tolerances of the tolerance-driven masters, comma-separated (default 1e-2,...,1e-4)",
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
    p.set_defaults(handler=_precision)

    p = sub.add_parser("sweep", help="run a scene's [sweep]: one run per value, CSV/PNG/table")
    p.add_argument("scene", type=Path)
    p.add_argument("--set", action="append", default=[], metavar="KEY=VALUE")
    p.add_argument("--output", type=Path, help="directory (default runs/<scene>/sweep)")
    p.add_argument("--workers", type=int, help="local processes (default: one per core)")
    p.add_argument("--dask", metavar="ADDRESS", help="run the sweep on this Dask scheduler")
    p.set_defaults(handler=_sweep)

    p = sub.add_parser("stability", help="run the stability suite (scenarios/stability/)")
    p.add_argument("--output", type=Path, default=Path("runs") / "stability")
    p.add_argument("--workers", type=int, help="local processes (default: one per core)")
    p.add_argument("--dask", metavar="ADDRESS", help="run the cases on this Dask scheduler")
    p.set_defaults(handler=_stability)

    p = sub.add_parser("bench", help="run a benchmark (prints ratios against its baseline)")
    p.add_argument("name", choices=["overhead", "m739"])
    p.set_defaults(handler=_bench)

    p = sub.add_parser("report", help="print the summary of a finished run")
    p.add_argument("run_dir", type=Path)
    p.set_defaults(handler=_report)

    args = parser.parse_args(argv)
    from fmus.build import BuildError

    try:
        return args.handler(args)
    except (ScenarioError, RunError, BuildError) as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2


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
    from orchestrator.run import run_scene
    from orchestrator.scenario import load_scene

    scene = load_scene(args.scene, _overrides(args.set))
    result = run_scene(scene, output_dir=args.output, show_progress=not args.no_progress)
    print(
        f"scene {scene.name}: {result.status}" + (f" — {result.message}" if result.message else "")
    )
    for name, q in result.headline.items():
        value = q["value"] if isinstance(q["value"], str) else f"{q['value']:.10g}"
        print(f"  {name:32s} {value} {q['unit']}")
    for name, value in result.accuracy.items():
        print(f"  {name:32s} {value:.4g}")
    for warning in result.stats.extra.get("warnings", []):
        print(f"  warning: {warning}")
    s = result.stats
    print(
        f"  steps {s.steps}, doSteps {s.do_steps}, rejections {s.rejections}, "
        f"rollbacks {s.rollbacks}, events {s.events}, wall time {s.wall_time:.3f} s"
    )
    print(f"  results in {result.output_dir}")
    return 0 if result.status == "completed" else 1


def _check(args: argparse.Namespace) -> int:
    from orchestrator.scenario import load_scene

    for path in args.scene:
        scene = load_scene(path)
        counts = f"{len(scene.fmus)} FMUs, {len(scene.connections)} connections"
        print(f"{path}: ok ({scene.name}, {counts})")
    return 0


def _build(args: argparse.Namespace) -> int:
    from fmus.build import build_fmu
    from fmus.registry import FMU_WRAPPERS

    for name in args.names or sorted(FMU_WRAPPERS):
        print(build_fmu(name, args.dest, force=args.force))
    return 0


def _validate(args: argparse.Namespace) -> int:
    from fmus.registry import FMU_WRAPPERS
    from orchestrator.fmu_checks import check_fmu

    failures = 0
    for name in args.names or sorted(FMU_WRAPPERS):
        problems = check_fmu(name)
        print(f"{name}: {'ok' if not problems else 'FAILED'}")
        for problem in problems:
            print(f"  - {problem}")
        failures += bool(problems)
    return 1 if failures else 0


def _crosscheck(args: argparse.Namespace) -> int:
    import numpy as np

    from orchestrator.crosscheck import run_with_libcosim
    from orchestrator.run import run_scene
    from orchestrator.scenario import load_scene

    scene = load_scene(args.scene, {"master.algorithm": "jacobi"})
    ours = run_scene(scene, show_progress=False)
    header, theirs = run_with_libcosim(scene)
    columns = [ours.header.index(h) for h in header]
    n = min(len(theirs), len(ours.data) - 1)
    diff = np.abs(theirs[:n] - ours.data[1 : n + 1][:, columns])
    for j, name in enumerate(header[1:], start=1):
        print(f"  {name:28s} max |ours - libcosim| = {diff[:, j].max():.3e}")
    worst = float(diff[:, 1:].max())
    print(f"largest difference {worst:.3e} over {n} steps of {scene.master.step} s")
    return 0 if worst <= 1e-9 else 1


def _precision(args: argparse.Namespace) -> int:
    from orchestrator.work_precision import (
        STEP_FACTORS,
        TOLERANCES,
        observed_order,
        work_precision,
    )

    rows = work_precision(
        args.scene,
        args.output,
        step_factors=args.step_factors or STEP_FACTORS,
        tolerances=args.tolerances or TOLERANCES,
        start_hold_tolerances=args.start_hold_tolerances or (),
        workers=args.workers,
        dask_address=args.dask,
    )
    for master in dict.fromkeys(r.master for r in rows):
        print(f"  {master:20s} observed order {observed_order(rows, master):.2f}")
    out = Path(rows[0].result.job.output_dir).parent if rows else args.output
    print(f"report in {out}/work_precision.md (.csv, .png)")
    return 0


def _sweep(args: argparse.Namespace) -> int:
    from orchestrator.parameter_sweep import run_sweep

    result = run_sweep(
        args.scene, args.output, args.workers, args.dask, _overrides(args.set) or None
    )
    print((result.output_dir / "sweep.md").read_text())
    print(f"results in {result.output_dir} (sweep.csv, sweep.png, sweep.md)")
    return 0 if all(r["status"] == "completed" for r in result.rows) else 1


def _stability(args: argparse.Namespace) -> int:
    from orchestrator.stability import run_suite

    rows = run_suite(out_dir=args.output, workers=args.workers, dask_address=args.dask)
    print((args.output / "stability.md").read_text())
    unstable = [r for r in rows if r.master == "regime-aware" and not r.stable and not r.diagnosis]
    return 1 if unstable else 0


def _bench(args: argparse.Namespace) -> int:
    from orchestrator.benchmarks import BENCHMARKS

    BENCHMARKS[args.name]()
    return 0


def _report(args: argparse.Namespace) -> int:
    summary_file = args.run_dir / "summary.json"
    if not summary_file.exists():
        print(f"error: {summary_file} not found: not a run directory", file=sys.stderr)
        return 2
    summary = json.loads(summary_file.read_text())
    print(
        json.dumps(
            {k: summary[k] for k in ("scene", "status", "message", "headline", "stats")}, indent=2
        )
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
