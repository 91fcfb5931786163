"""What every run plot shares: regimes as named bands, switches and impacts marked at the
times the run located them (its ``events.csv``), one axis per quantity with its unit, and
recorded values drawn where they were recorded.

A run records one row per macro step (``output.every``): between two rows nothing is known,
so a sparse record is drawn as markers (with a faint line to guide the eye), not as a line
that looks like a trajectory.
"""

from __future__ import annotations

import csv
from collections.abc import Iterable, Sequence
from functools import cache
from pathlib import Path
from typing import Any

import numpy as np

#: Fewer recorded points than this in view: each is drawn as a marker.
SPARSE_POINTS = 400
#: Band colours, one per regime in the order the component numbers them.
BAND_COLOURS = ("#dddddd", "#9ecae1", "#fdae6b", "#a1d99b", "#bcbddc", "#fc9272", "#c7e9c0")

Event = tuple[float, str, str, str]  # (time, subsystem, from, to), as events.csv holds them


@cache
def pyplot() -> Any:
    """matplotlib's pyplot, drawing to files only (imported, and its backend chosen, once:
    only a run that plots pays for it)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def regime_names(scene: Any, instance: str) -> dict[int, str]:
    """The names of an FMU's regimes: its component's ``REGIME_NAMES``, else those its model
    description declares (the regime output's Enumeration); none for a black box."""
    try:
        names = getattr(scene.component_class(instance), "REGIME_NAMES", None)
    except Exception:  # noqa: BLE001 - an FMU of another tool has no component class
        names = None
    if names:
        return dict(names)
    model = getattr(scene.fmus[instance], "model", None)
    return dict(getattr(model, "regime_names", {}) or {})


def run_events(path: Path) -> list[Event]:
    """The located switches of the run whose plot is ``path``: its ``events.csv`` beside
    it (none if there is no such file)."""
    file = Path(path).parent / "events.csv"
    if not file.exists():
        return []
    with open(file, newline="") as f:
        rows = list(csv.reader(f))[1:]
    return [(float(r[0]), r[1], r[2], r[3]) for r in rows if len(r) == 4]


def of(events: Iterable[Event], subsystem: str) -> list[Event]:
    return [e for e in events if e[1] == subsystem]


def regime_spans(
    t: np.ndarray,
    regime: np.ndarray,
    names: dict[int, str],
    events: Sequence[Event] = (),
) -> list[tuple[float, float, str]]:
    """(start, end, name) of each stretch in one regime over [t[0], t[-1]].

    With the subsystem's located switches (``events``) the stretches start and end at them;
    without, a regime holds from the row that first records it to the next row that records
    another (all that a record without events can tell)."""
    t = np.asarray(t, dtype=float)
    if len(t) == 0:
        return []
    regime = np.asarray(regime).astype(int)
    name = names.get(int(regime[0]), str(int(regime[0])))
    spans: list[tuple[float, float, str]] = []
    if events:
        start = float(t[0])
        for te, _, _, to in sorted(events):
            if te <= t[0]:
                name = to
                continue
            if te >= t[-1]:
                break
            spans.append((start, te, name))
            start, name = te, to
        spans.append((start, float(t[-1]), name))
        return spans
    change = np.nonzero(np.diff(regime))[0] + 1
    bounds = [0, *change.tolist(), len(t) - 1]
    for a, b in zip(bounds[:-1], bounds[1:], strict=True):
        if t[b] > t[a]:
            spans.append((float(t[a]), float(t[b]), names.get(int(regime[a]), str(regime[a]))))
    return spans


def regime_colours(names: dict[int, str], first: int = 0) -> dict[str, str]:
    """One colour per regime name, in the component's order from the ``first`` colour (two
    subsystems drawn together start at different colours)."""
    n = len(BAND_COLOURS)
    return {name: BAND_COLOURS[(first + i) % n] for i, name in enumerate(names.values())}


def regime_bands(
    ax: Any,
    spans: Sequence[tuple[float, float, str]],
    colours: dict[str, str],
    scale: float = 1.0,
    y: tuple[float, float] = (0.0, 1.0),
    alpha: float = 1.0,
) -> list[Any]:
    """Shade each span in its regime's colour (times multiplied by ``scale``, the band over
    the axes fraction ``y``); returns one legend handle per regime met, labelled by name."""
    from matplotlib.patches import Patch

    seen: dict[str, Any] = {}
    for a, b, name in spans:
        colour = colours.setdefault(name, BAND_COLOURS[len(colours) % len(BAND_COLOURS)])
        ax.axvspan(a * scale, b * scale, ymin=y[0], ymax=y[1], color=colour, alpha=alpha, lw=0)
        seen.setdefault(name, Patch(facecolor=colour, alpha=alpha, label=name))
    return [seen[n] for n in colours if n in seen]


def regime_strip(
    ax: Any,
    rows: Sequence[tuple[str, Sequence[tuple[float, float, str]], dict[str, str]]],
    scale: float = 1.0,
) -> None:
    """One band row per subsystem (label, spans, colours) on ``ax``, each regime named in a
    legend beside the strip."""
    n = len(rows)
    handles: list[Any] = []
    for k, (_, spans, colours) in enumerate(rows):
        top = 1.0 - k / n
        handles += regime_bands(ax, spans, colours, scale, (top - 1.0 / n + 0.08 / n, top))
    ax.set_yticks([1.0 - (k + 0.5) / n for k in range(n)])
    ax.set_yticklabels([label for label, _, _ in rows])
    ax.set_ylim(0.0, 1.0)
    ax.tick_params(axis="y", length=0)
    ax.legend(
        handles=handles,
        loc="upper left",
        bbox_to_anchor=(1.005, 1.0),
        fontsize=8,
        title="regime",
        title_fontsize=8,
        frameon=False,
    )


def event_lines(
    axes: Iterable[Any],
    times: Iterable[float],
    scale: float = 1.0,
    colour: str = "C3",
    style: str = "-",
    width: float = 0.8,
) -> None:
    """A vertical line at each time on every axes (located switches or impacts)."""
    times = [t * scale for t in times]
    for ax in axes:
        for t in times:
            ax.axvline(t, color=colour, ls=style, lw=width, alpha=0.7, zorder=1)


def recorded(ax: Any, t: np.ndarray, y: np.ndarray, *, steps: bool = False, **style: Any) -> Any:
    """Recorded values where they were recorded: markers when the points in view are few
    (a faint line between them), a line when they are dense; ``steps`` holds each value
    until the next row (a count or a regime)."""
    if steps:
        (line,) = ax.step(t, y, where="post", **style)
        return line
    if len(t) < SPARSE_POINTS:
        colour = style.pop("color", None)
        (line,) = ax.plot(t, y, ".", ms=4, color=colour, **style)
        ax.plot(t, y, "-", lw=0.6, alpha=0.35, color=line.get_color())
        return line
    (line,) = ax.plot(t, y, "-", lw=0.9, **style)
    return line


def column_unit(scene: Any, column: str) -> str:
    """The unit an FMU declares for a recorded column ``instance.variable`` ("1": none)."""
    instance, _, name = column.partition(".")
    model = getattr(scene.fmus.get(instance), "model", None)
    variable = getattr(model, "variables", {}).get(name)
    return getattr(variable, "unit", None) or "1"


def unit_label(ax: Any, quantity: str, unit: str, colour: str | None = None) -> None:
    """Label an axis with its quantity and unit."""
    ax.set_ylabel(f"{quantity} [{unit}]", **({"color": colour} if colour else {}))


def window(t: np.ndarray, start: float, end: float) -> np.ndarray:
    """The rows recorded within [start, end]."""
    return (t >= start) & (t <= end)


def save_figure(fig: Any, path: Path, title: str | None = None, tight: bool = True) -> None:
    """Title, tight layout (unless ``tight`` is false: a figure laid out by hand), PNG at
    ``path``, figure closed.  A figure laid out by hand sets no layout engine: with one,
    saving draws the whole figure twice (0.6-0.9 s of the M739 plot)."""
    if title:
        fig.suptitle(title)
    if tight and fig.get_layout_engine() is None:  # a figure made with a layout keeps it
        fig.tight_layout()
    fig.savefig(path, dpi=110)
    pyplot().close(fig)
