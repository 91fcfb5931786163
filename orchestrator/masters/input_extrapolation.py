"""The single pass's held inputs: each exchanged signal extrapolated over the next step
from the last exchange points of the same regime (masters/single_pass.py)."""

from __future__ import annotations

Slot = tuple[int, int]  # (instance, index of a Real output)


class InputExtrapolation:
    """Per exchanged Real signal: its values at the last exchange points where it was
    continuous, to extrapolate it over the next step by the polynomial through them
    (Newton form: linear through one previous point, quadratic through two)."""

    def __init__(self, signals: list[Slot], points: int) -> None:
        self.signals = signals
        self.points = points
        self.history: dict[Slot, list[tuple[float, float]]] = {s: [] for s in signals}
        #: per signal (first divided difference, second divided difference, t - t1)
        self.coefficients: dict[Slot, tuple[float, float, float]] = {}
        self.carried: dict[Slot, float] = {}

    def prepare(self, t: float, values: list[list[float]]) -> None:
        """The extrapolation for the step from t (values: those read at t)."""
        coefficients = {}
        for s, hist in self.history.items():
            v = values[s[0]][s[1]]
            if not hist or hist[-1][0] >= t:
                slope = self.carried.get(s)
                if slope is not None:
                    coefficients[s] = (slope, 0.0, 0.0)
                continue
            t1, v1 = hist[-1]
            d1 = (v - v1) / (t - t1)
            d2 = 0.0
            if len(hist) > 1:
                t0, v0 = hist[-2]
                d2 = (d1 - (v1 - v0) / (t1 - t0)) / (t - t0)
            coefficients[s] = (d1, d2, t - t1)
        self.coefficients = coefficients
        self.carried = {}

    def accepted(self, t: float, values: list[list[float]]) -> None:
        """The step from t was accepted without a switch: t is the last point now."""
        for s, hist in self.history.items():
            hist.append((t, values[s[0]][s[1]]))
            del hist[: -self.points]

    def switched(self, internal: bool) -> None:
        """The step ended on a switch.  At a regime change every signal starts anew.  At
        an FMU's internal event (a friction sign, a mesh piece) the signals go on at the
        slopes they had: a jump there would spoil a slope through it, and a kink (the
        others' rates change with the event) would spoil one kept across it (so would
        keeping the points of the signals that did not jump)."""
        for s, hist in self.history.items():
            hist.clear()
            c = self.coefficients.get(s)
            if internal and c is not None:
                self.carried[s] = c[0]

    def mean(self, source: Slot, start: float, h: float) -> float:
        """Mean over [t, t+h] of the extrapolated signal."""
        c = self.coefficients.get(source)
        if c is None:
            return start
        return start + c[0] * 0.5 * h + c[1] * (h * h / 3.0 + 0.5 * c[2] * h)

    def slope(self, source: Slot) -> float:
        """The extrapolated signal's time derivative at the step start (0: held)."""
        c = self.coefficients.get(source)
        return 0.0 if c is None else c[0] + c[1] * c[2]

    @property
    def second_order(self) -> bool:
        return bool(self.coefficients)
