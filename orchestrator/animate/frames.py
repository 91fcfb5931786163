"""Frames of an animation: when each is taken, how it is drawn, where it is written.

The static parts of a picture are drawn once and kept as a background; each frame restores
it and draws only the moving artists on it (blitting on matplotlib's Agg canvas).  The GIF
is written a frame at a time with Pillow (each frame the rectangle that changed, one palette
for all), so a long animation never sits in memory; an MP4 goes to ffmpeg through a pipe.
"""

from __future__ import annotations

import shutil
import subprocess
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any, BinaryIO

import numpy as np

#: Refused beyond this many frames: the window, slowdown or duration should be chosen.
MAX_FRAMES = 20_000
#: Colours of the GIF palette (matplotlib's lines and anti-aliasing fit in this).
PALETTE_COLOURS = 128


@dataclass(frozen=True)
class Clock:
    """Frame k shows the simulated time start + k / (fps slowdown)."""

    start: float
    stop: float
    fps: float
    slowdown: float

    @property
    def frame_step(self) -> float:
        """Simulated time between two frames [s]."""
        return 1.0 / (self.fps * self.slowdown)

    @property
    def count(self) -> int:
        return int(np.floor((self.stop - self.start) / self.frame_step + 1e-9)) + 1

    def times(self) -> np.ndarray:
        t = self.start + np.arange(self.count) * self.frame_step
        # A window of whole frames ends on its stop, not a rounding error before it.
        if abs(t[-1] - self.stop) < 1e-6 * self.frame_step:
            t[-1] = self.stop
        return t

    def delays_ms(self) -> Iterator[int]:
        """Each frame's display time in whole hundredths of a second (the GIF's unit), so
        that the frames' sum keeps to the clock."""
        k = 0
        while True:
            a = round(k * 100.0 / self.fps)
            b = round((k + 1) * 100.0 / self.fps)
            yield 10 * max(b - a, 1)
            k += 1


class GifStream:
    """A GIF written as frames come: the first whole, each next one the box that changed."""

    def __init__(self, path: Path) -> None:
        self.path = Path(path)
        self._file: BinaryIO | None = None
        self._palette: Any = None
        self._previous: np.ndarray | None = None
        self.frames = 0

    def add(self, rgb: np.ndarray, delay_ms: int) -> None:
        from PIL import GifImagePlugin, Image

        image = Image.fromarray(rgb, "RGB")
        if self._palette is None:
            self._palette = image.quantize(PALETTE_COLOURS, method=Image.Quantize.MEDIANCUT)
            self._file = open(self.path, "wb")
            frame = self._palette
            header, _ = GifImagePlugin.getheader(frame, info={"loop": 0})
            for chunk in header:
                self._file.write(chunk)
            box = (0, 0, *frame.size)
        else:
            frame = image.quantize(palette=self._palette, dither=Image.Dither.NONE)
            box = _changed_box(self._previous, np.asarray(frame))
            if box is None:  # unchanged: a pixel-sized frame keeps the timing
                box = (0, 0, 1, 1)
        self._previous = np.asarray(frame)
        assert self._file is not None
        part = frame.crop(box) if box != (0, 0, *frame.size) else frame
        for chunk in GifImagePlugin.getdata(part, offset=box[:2], duration=delay_ms):
            self._file.write(chunk)
        self.frames += 1

    def close(self) -> None:
        if self._file is not None:
            self._file.write(b";")
            self._file.close()
            self._file = None


def _changed_box(a: np.ndarray | None, b: np.ndarray) -> tuple[int, int, int, int] | None:
    if a is None:
        return (0, 0, b.shape[1], b.shape[0])
    rows = np.flatnonzero((a != b).any(axis=1))
    if rows.size == 0:
        return None
    cols = np.flatnonzero((a != b).any(axis=0))
    return (int(cols[0]), int(rows[0]), int(cols[-1]) + 1, int(rows[-1]) + 1)


class Mp4Stream:
    """An H.264 MP4 through ffmpeg (when it is installed): raw RGB frames on its input."""

    def __init__(self, path: Path, size: tuple[int, int], fps: float) -> None:
        exe = shutil.which("ffmpeg")
        assert exe is not None
        w, h = size
        self.path = Path(path)
        self._process = subprocess.Popen(
            [exe, "-loglevel", "error", "-y", "-f", "rawvideo", "-pix_fmt", "rgb24",
             "-s", f"{w}x{h}", "-r", f"{fps:g}", "-i", "-",
             "-vf", "pad=ceil(iw/2)*2:ceil(ih/2)*2", "-pix_fmt", "yuv420p",
             "-vcodec", "libx264", str(path)],
            stdin=subprocess.PIPE,
        )  # fmt: skip

    def add(self, rgb: np.ndarray, delay_ms: int) -> None:
        assert self._process.stdin is not None
        self._process.stdin.write(np.ascontiguousarray(rgb).tobytes())

    def close(self) -> None:
        assert self._process.stdin is not None
        self._process.stdin.close()
        if self._process.wait() != 0:
            raise OSError(f"ffmpeg failed writing {self.path}")


def mp4_available() -> bool:
    return shutil.which("ffmpeg") is not None


def render(
    fig: Any,
    animated: list[Any],
    update: Callable[[float], None],
    clock: Clock,
    writers: list[Any],
    progress: Callable[[], None] | None = None,
) -> None:
    """Every frame of ``clock``: ``update(t)`` moves the artists, which are drawn over the
    background and handed to each writer."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    canvas = FigureCanvasAgg(fig)
    for artist in animated:
        artist.set_animated(True)
    canvas.draw()
    background = canvas.copy_from_bbox(fig.bbox)
    delays = clock.delays_ms()
    for t in clock.times():
        update(float(t))
        canvas.restore_region(background)
        for artist in animated:
            fig.draw_artist(artist)
        rgb = np.asarray(canvas.buffer_rgba())[:, :, :3]
        delay = next(delays)
        for writer in writers:
            writer.add(rgb, delay)
        if progress is not None:
            progress()
