"""The tolerance-study test scene: two undamped inertias whose peak coupling torque has a
closed-form distribution (tests/orchestrator/test_study.py, test_study_inputs.py)."""

from __future__ import annotations

from pathlib import Path

# The two inertias undamped: the relative motion is an oscillator of reduced inertia
# Jr = Ja Jb / (Ja + Jb) started at relative speed w, so the peak coupling torque is
# w sqrt(Jr k).  With k and w lognormal, the peak torque is lognormal too.
JA, JB = 2e-4, 1e-4
JR = JA * JB / (JA + JB)
K_MEDIAN, K_SIGMA = 2.0, 0.2
W_MEDIAN, W_SIGMA = 10.0, 0.1
SCENE = f"""
[scene]
name = "peak_torque"
stop = "15 ms"

[fmus.a]
component = "Inertia"
parameters = {{ J = {JA}, phi0 = 0.0, w0 = {W_MEDIAN} }}

[fmus.b]
component = "SpringDamperInertia"
parameters = {{ J = {JB}, k = {K_MEDIAN}, d = 0.0, phi0 = 0.0, w0 = 0.0 }}
inputs = {{ phi_in = 0.0, w_in = {W_MEDIAN} }}

[[connections]]
ports = ["a.flange", "b.coupling"]

[master]
algorithm = "jacobi"
step = "40 us"

[output]
record = ["a.phi", "b.tau"]

[report.headline]
peak_coupling_torque = {{ signal = "b.tau", reduce = "maxabs" }}
"""
STUDY = """
[study]
samples = 80
seed = 11
sampling = "sobol"
quantities = ["peak_coupling_torque"]

[[study.inputs]]
key = "fmus.b.parameters.k"
distribution = "lognormal"
median = "2 N*m/rad"
sigma = 0.2

[[study.inputs]]
key = ["fmus.a.parameters.w0", "fmus.b.inputs.w_in"]
name = "w0"
distribution = "lognormal"
median = "10 rad/s"
sigma = 0.1

[study.limits.peak_coupling_torque]
max = 0.15
max_means = "overloads the shaft"
"""


LOGNORMAL_K = 'distribution = "lognormal"\nmedian = "2 N*m/rad"\nsigma = 0.2'


def scene_file(tmp_path: Path, study: str = STUDY, name: str = "study.toml") -> Path:
    path = tmp_path / name
    path.write_text(SCENE + study)
    return path
