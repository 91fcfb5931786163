"""What the scene and SSP fuzz tests share: odd values, hypothesis settings, and what a
clear refusal looks like (tests/orchestrator/test_fuzz_scenes.py, test_fuzz_ssp.py)."""

from __future__ import annotations

from hypothesis import HealthCheck

WEIRD_TEXT = [
    "nan s", "-1 s", "1e300 s", "inf rpm", "-inf", "abc", "", "0 s", "1e-300 ms", "5 kg",
    "1e12 rpm", "-30000 rpm", "0.5 ms", "1 m", "nan", "1e-12 s", "NaN rad/s", "2 ** 2000",
]  # fmt: skip

COMMON = dict(
    deadline=None,
    suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow],
    derandomize=True,
)


def assert_clear(code: int, err: str, allowed: tuple[int, ...]) -> None:
    assert code in allowed, err
    assert "Traceback" not in err, err
    if code == 2:
        assert err.startswith("error: ") and err.count("\n") == 1, err
