"""Fixtures of the FMU tests: the foreign (C) test FMUs, built once per test process."""

from __future__ import annotations

import foreign_fmus
import pytest
from foreign_fmus import ForeignFmus


@pytest.fixture(scope="session")
def foreign(tmp_path_factory: pytest.TempPathFactory) -> ForeignFmus:
    if foreign_fmus.c_compiler() is None:
        pytest.skip("no C compiler to build the foreign test FMUs")
    dest = tmp_path_factory.mktemp("foreign_fmus")
    try:
        body = foreign_fmus.build_torsion_body(dest)
        stateless = foreign_fmus.build_torsion_body(dest, can_get_set_state=False)
    except foreign_fmus.ForeignFmuError as exc:
        pytest.skip(str(exc))
    container = foreign_fmus.build_container(dest, body, fixed_step=1e-3)
    return ForeignFmus(dest, body, stateless, container)
