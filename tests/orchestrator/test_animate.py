"""``mechcosim animate``: every example family animates from a short run, the GIF holds the
frames and size asked for, and a frame shows the verge where the recorded angle puts it."""

from __future__ import annotations

import csv
import math
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from orchestrator.animate import AnimationOptions, animate_run
from orchestrator.cli import main
from orchestrator.run import run_scene
from orchestrator.scenario import load_scene
from orchestrator.scenes.m739.design import scene_design

SCENARIOS = Path(__file__).resolve().parents[2] / "scenarios"

#: matplotlib's "C3", the colour drawing.py gives the pallet faces.
FACE_RGB = np.array([0xD6, 0x27, 0x28])


def short_run(tmp_path: Path, fmu_cache: Path, scene_file: str, stop: str) -> Path:
    scene = load_scene(SCENARIOS / scene_file, {"scene.stop": stop})
    out = tmp_path / scene.name
    result = run_scene(
        scene,
        output_dir=out,
        cache_dir=fmu_cache,
        show_progress=False,
        compare_reference=False,
        plots=False,
    )
    assert result.status == "completed"
    return out


@pytest.fixture(scope="module")
def m739_run(tmp_path_factory: pytest.TempPathFactory, fmu_cache: Path) -> Path:
    return short_run(tmp_path_factory.mktemp("animate"), fmu_cache, "m739.toml", "1.2 ms")


@pytest.mark.parametrize(
    ("scene_file", "stop"),
    [
        ("clock_train_sa.toml", "1 ms"),
        ("lever_unit_decay.toml", "0.1 s"),
        ("press_feed_run1.toml", "10 ms"),
        ("mesh_efficiency.toml", "5 ms"),
    ],
)
def test_every_family_animates_from_a_short_run(
    tmp_path: Path, fmu_cache: Path, scene_file: str, stop: str
) -> None:
    run_dir = short_run(tmp_path, fmu_cache, scene_file, stop)
    made = animate_run(run_dir, tmp_path / "a.gif", AnimationOptions(fps=10, size=(320, 160),
                       duration=0.4, mp4=False))  # fmt: skip
    assert made.frames == 5  # 0.4 s at 10 frames/s, both ends shown
    with Image.open(made.gif) as gif:
        assert (gif.n_frames, gif.size) == (5, (320, 160))


def test_the_cli_writes_the_gif_and_says_so(
    m739_run: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "m.gif"
    args = ["animate", str(m739_run), "--output", str(out), "--stop", "0.2 ms"]
    assert main([*args, "--fps", "10", "--size", "300x150", "--no-mp4", "--no-progress"]) == 0
    # 0.2 ms at the M739's 1000x slower: 0.2 s, two frames at 10 frames/s and the first
    with Image.open(out) as gif:
        assert (gif.n_frames, gif.size) == (3, (300, 150))
    assert "3 frames of 300x150" in capsys.readouterr().out


@pytest.mark.parametrize(
    ("flag", "value", "named"),
    [("--stop", "5 kg", "--stop"), ("--size", "12", "--size"), ("--start", "1 s", "--start")],
)
def test_bad_options_are_one_line_errors(
    m739_run: Path, flag: str, value: str, named: str, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["animate", str(m739_run), flag, value, "--no-progress"]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("error: ") and named in err and len(err.splitlines()) == 1


def test_a_directory_without_a_run_is_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["animate", str(tmp_path)]) == 2
    assert "summary.json: not found" in capsys.readouterr().err


def recorded(run_dir: Path) -> tuple[np.ndarray, np.ndarray, list[str]]:
    with open(run_dir / "timeseries.csv", newline="") as f:
        rows = list(csv.reader(f))
    header = rows[0]
    data = np.array(rows[1:], dtype=float)
    return data[:, 0], data[:, header.index("verge.psi")], header


def faces(psi: float) -> list[tuple[np.ndarray, np.ndarray]]:
    """Where the recorded verge angle puts the pallet faces, (start, end) [in]: each from its
    corner (radius C; the entrance at psi, the exit lambda behind) along the face angle
    alpha, 0.35 C long, the exit face drawn the other way (drawing.py)."""
    d = scene_design(load_scene(SCENARIOS / "m739.toml"))
    c = d.c / 0.0254
    out = []
    for angle, alpha, side in ((psi, d.alpha_en, 1.0), (psi - d.lam, d.alpha_ex, -1.0)):
        corner = np.array([c * math.cos(angle), c * math.sin(angle)])
        along = side * 0.35 * c * np.array([math.cos(angle + alpha), math.sin(angle + alpha)])
        out.append((corner, corner + along))
    return out


def off_segment(points: np.ndarray, a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, float]:
    """Each point's distance from segment a-b, and the share of the segment they cover."""
    ab = b - a
    s = np.clip((points - a) @ ab / (ab @ ab), 0.0, 1.0)
    distance = np.linalg.norm(points - (a + s[:, None] * ab), axis=1)
    return distance, float(s.max() - s.min())


def test_a_frame_shows_the_verge_at_the_recorded_angle(m739_run: Path, tmp_path: Path) -> None:
    t, psi, _ = recorded(m739_run)
    # Two recorded instants with the verge far apart: on the entrance face at the start,
    # on the exit face at its largest angle before 1.2 ms.
    i1, i2 = 0, int(np.argmax(psi))
    assert psi[i2] - psi[i1] > 0.1
    frames = 8
    made = animate_run(
        m739_run,
        tmp_path / "v.gif",
        AnimationOptions(start=t[i1], stop=t[i2], fps=10, size=(1000, 500),
                         duration=frames / 10, mp4=False),
    )  # fmt: skip
    assert made.frames == frames + 1
    box = made.layout["escapement"]
    (left, top, right, bottom), (x0, x1), (y0, y1) = box["pixels"], box["xlim"], box["ylim"]

    def pixel(x: float, y: float) -> np.ndarray:
        return np.array(
            [
                left + (x - x0) / (x1 - x0) * (right - left),
                top + (y1 - y) / (y1 - y0) * (bottom - top),
            ]
        )

    centres = []
    with Image.open(made.gif) as gif:
        for k, i in ((0, i1), (frames, i2)):
            gif.seek(k)
            rgb = np.asarray(gif.convert("RGB")).astype(int)
            region = rgb[int(top) : int(bottom), int(left) : int(right)]
            near = np.abs(region - FACE_RGB).max(axis=2) < 30
            rows, cols = np.nonzero(near)
            rows, cols = rows + int(top), cols + int(left)
            above = rows < pixel(0.0, 0.0)[1]  # the entrance face above O_p, the exit below
            points = np.column_stack([cols, rows]).astype(float)
            for face, (a, b) in zip((above, ~above), faces(psi[i]), strict=True):
                assert face.sum() > 30, f"frame {k}: a pallet face is not drawn"
                # Every face pixel on the face where the recorded angle puts it (the line is
                # 2.5 points wide), and the drawn face as long as the design's.
                distance, covered = off_segment(points[face], pixel(*a), pixel(*b))
                assert np.percentile(distance, 95) < 2.5, (k, np.percentile(distance, 95))
                assert covered > 0.8, (k, covered)
                centres.append(points[face].mean(axis=0))
    # The verge moved between the two frames (not a frozen picture): its faces by more
    # than 10 pixels, as the recorded angles say.
    assert np.linalg.norm(centres[2] - centres[0]) > 10.0
