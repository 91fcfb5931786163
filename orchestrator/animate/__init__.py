"""``mechcosim animate RUN_DIR``: the mechanism of a run drawn to scale from its design,
moving with the recorded angles, in slow motion (a GIF always, an MP4 where ffmpeg is).

A family's stage (``STAGES``) draws its mechanism once and moves its artists to any time of
the run; ``frames`` takes the frames and writes them.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field
from importlib import import_module
from pathlib import Path
from typing import Any

from orchestrator.errors import ScenarioError

#: Family -> "module:class" of its stage (imported when a run of that family is drawn).
STAGES = {
    "m739": "orchestrator.animate.escapement:EscapementStage",
    "clock_train": "orchestrator.animate.escapement:EscapementStage",
    "detached_lever": "orchestrator.animate.schematics:LeverStage",
    "press_feed": "orchestrator.animate.schematics:PressFeedStage",
    "gear_mesh": "orchestrator.animate.schematics:GearMeshStage",
}
DEFAULT_FPS = 25.0
DEFAULT_SIZE = (880, 440)


@dataclass(frozen=True)
class AnimationOptions:
    start: float | None = None  # simulated time window [s]; default the whole run
    stop: float | None = None
    fps: float = DEFAULT_FPS
    size: tuple[int, int] = DEFAULT_SIZE  # pixels
    slowdown: float | None = None  # simulated time runs this many times slower
    duration: float | None = None  # or: the window lasts this long [s of animation]
    mp4: bool = True  # also an MP4 where ffmpeg is installed


@dataclass
class Animation:
    gif: Path
    mp4: Path | None
    frames: int
    size: tuple[int, int]
    start: float
    stop: float
    slowdown: float
    fps: float
    wall_time: float
    notes: list[str] = field(default_factory=list)
    layout: dict[str, Any] = field(default_factory=dict)  # where the stage drew what

    @property
    def seconds_per_frame(self) -> float:
        return self.wall_time / self.frames


def stage_for(run: Any) -> Any:
    family = getattr(run.scene, "family", None)
    if family not in STAGES:
        raise ScenarioError(
            run.directory / "summary.json",
            "report.family",
            f"{family!r} has no animation; animated are the families {sorted(STAGES)}",
        )
    module, name = STAGES[family].split(":")
    return getattr(import_module(module), name)(run)


def animate_run(
    run_dir: Path,
    output: Path | None = None,
    options: AnimationOptions = AnimationOptions(),
    progress: Callable[[int], Callable[[], None]] | None = None,
) -> Animation:
    """Write the animation of the run in ``run_dir`` (default ``<run_dir>/<scene>.gif``).

    ``progress(total)`` gives a function called once per frame drawn."""
    from matplotlib.figure import Figure

    from orchestrator.animate.frames import (
        MAX_FRAMES,
        GifStream,
        Mp4Stream,
        mp4_available,
        render,
    )
    from orchestrator.animate.record import read_run

    began = time.perf_counter()
    run = read_run(run_dir)
    stage = stage_for(run)
    clock = _clock(run, stage, options)
    if clock.count > MAX_FRAMES:
        raise ScenarioError(
            "--stop/--slowdown/--duration",
            "",
            f"{clock.count} frames ({clock.stop - clock.start:.6g} s simulated at "
            f"{clock.slowdown:g}x slower, {clock.fps:g} frames/s): at most {MAX_FRAMES}; "
            "choose a shorter window, a smaller slowdown or a duration",
        )
    name = run.summary.get("scene", "animation")
    gif = Path(output) if output else Path(run_dir) / f"{name}.gif"
    if gif.suffix.lower() != ".gif":
        raise ScenarioError(gif, "", "expected a .gif file name (the MP4 goes beside it)")
    w, h = options.size
    dpi = 100.0
    fig = Figure(figsize=(w / dpi, h / dpi), dpi=dpi)
    animated = stage.build(fig, clock.frame_step)
    title = fig.text(0.5, 0.975, "", ha="center", va="top", fontsize=9)
    animated.append(title)

    def update(t: float) -> None:
        stage.update(t)
        title.set_text(f"{name}: t = {t * 1e3:.4f} ms (simulated), slow motion {clock.slowdown:g}x")

    writers: list[Any] = [GifStream(gif)]
    mp4 = gif.with_suffix(".mp4") if options.mp4 and mp4_available() else None
    if mp4 is not None:
        writers.append(Mp4Stream(mp4, (w, h), clock.fps))
    tick = progress(clock.count) if progress else None
    try:
        render(fig, animated, update, clock, writers, tick)
    finally:
        for writer in writers:
            writer.close()
    layout = stage.layout() if hasattr(stage, "layout") else {}
    return Animation(
        gif, mp4, clock.count, (w, h), clock.start, clock.stop, clock.slowdown, clock.fps,
        time.perf_counter() - began, list(run.notes), layout,
    )  # fmt: skip


def _clock(run: Any, stage: Any, options: AnimationOptions) -> Any:
    from orchestrator.animate.frames import Clock

    first, last = float(run.time[0]), float(run.time[-1])
    start = first if options.start is None else options.start
    stop = last if options.stop is None else min(options.stop, last)
    if not first <= start < stop:
        raise ScenarioError(
            "--start/--stop",
            "",
            f"window {start:.6g} .. {stop:.6g} s: expected start < stop within the run's "
            f"{first:.6g} .. {last:.6g} s",
        )
    if options.fps <= 0.0:
        raise ScenarioError("--fps", "", f"{options.fps:g}: expected a positive frame rate")
    if options.duration is not None:
        if options.duration <= 0.0:
            raise ScenarioError("--duration", "", "expected a positive time")
        slowdown = options.duration / (stop - start)
    else:
        slowdown = options.slowdown or stage.default_slowdown
    if slowdown <= 0.0:
        raise ScenarioError("--slowdown", "", f"{slowdown:g}: expected a positive factor")
    return Clock(start, stop, options.fps, slowdown)
