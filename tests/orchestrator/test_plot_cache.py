"""A run's plot is copied from the cache when its data, events, scene and drawing code are
those of a plot drawn before, and drawn again when any of them differs."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from orchestrator.plot_cache import cached_plot
from orchestrator.scenario import load_scene

pytestmark = pytest.mark.orchestrator
PROJECT = Path(__file__).resolve().parents[2]


class _Drawer:
    """Writes a PNG's stand-in naming how many times it has drawn."""

    def __init__(self, path: Path) -> None:
        self.path, self.count = path, 0

    def __call__(self) -> None:
        self.count += 1
        self.path.write_bytes(f"drawing {self.count}".encode())


def test_the_same_content_is_copied_and_a_change_drawn(tmp_path: Path) -> None:
    scene = load_scene(PROJECT / "scenarios" / "two_inertias.toml", {})
    header = ["time", "a.phi"]
    data = np.array([[0.0, 0.0], [1e-3, 0.5]])
    out = tmp_path / "run"
    out.mkdir()
    png = out / "plot.png"
    (out / "events.csv").write_text("time,subsystem,from,to\n")
    draw = _Drawer(png)
    cache = tmp_path / "cache"

    assert cached_plot(scene, header, data, png, draw, cache) is False
    png.unlink()
    assert cached_plot(scene, header, data, png, draw, cache) is True
    assert (draw.count, png.read_bytes()) == (1, b"drawing 1")

    changed = data.copy()
    changed[1, 1] = np.nextafter(0.5, 1.0)  # one value, one bit
    assert cached_plot(scene, header, changed, png, draw, cache) is False
    (out / "events.csv").write_text("time,subsystem,from,to\n0.0005,a,0,1\n")
    assert cached_plot(scene, header, data, png, draw, cache) is False
    other = load_scene(PROJECT / "scenarios" / "two_inertias.toml", {"scene.stop": "2 ms"})
    assert cached_plot(other, header, data, png, draw, cache) is False
    assert draw.count == 4
    assert len(list((cache / "plots").rglob("*.png"))) == 4


def test_a_run_copies_the_plot_drawn_before(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    from orchestrator import plot_cache
    from orchestrator.run import run_scene

    monkeypatch.setattr(plot_cache, "plot_dir", lambda cache_dir: tmp_path / "plots")
    scene = load_scene(PROJECT / "scenarios" / "lever_unit_decay.toml", {"scene.stop": "50 ms"})
    first = run_scene(scene, tmp_path / "a", show_progress=False, compare_reference=False)
    second = run_scene(scene, tmp_path / "b", show_progress=False, compare_reference=False)
    png = f"{scene.name}.png"
    assert "plot: draw and write the PNG" in first.phases
    assert "plot (from the cache)" in second.phases
    assert "plot: draw and write the PNG" not in second.phases
    assert (tmp_path / "a" / png).read_bytes() == (tmp_path / "b" / png).read_bytes()
    assert (tmp_path / "a" / png).read_bytes().startswith(b"\x89PNG")
