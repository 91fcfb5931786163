"""Results kept beside the FMUs between processes (fmus.disk_memo): read back as written,
passed over when half-written, and used by the FMU records so that a later process does
not parse the component modules again."""

from __future__ import annotations

from pathlib import Path

import pytest

from fmus import registry
from fmus.disk_memo import DiskMemo


@pytest.fixture
def cache(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    monkeypatch.setenv("MECHCOSIM_FMU_CACHE", str(tmp_path))
    return tmp_path


def test_a_memo_reads_back_what_it_kept(cache: Path) -> None:
    DiskMemo("m").put("a", 0.1 + 0.2)
    assert DiskMemo("m").get("a") == 0.1 + 0.2  # a new reader: from the file, to the bit
    assert DiskMemo("m").get("b") is None
    assert (cache / "memo" / "m.json").is_file()


def test_a_half_written_memo_is_passed_over(cache: Path) -> None:
    DiskMemo("m").put("a", 1.0)
    path = cache / "memo" / "m.json"
    path.write_text(path.read_text()[:5])
    memo = DiskMemo("m")
    assert memo.get("a") is None
    memo.put("b", 2.0)  # and written whole again
    assert DiskMemo("m").get("b") == 2.0


def test_a_module_parsed_once_is_not_parsed_again(
    cache: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    source = tmp_path / "a.py"
    source.write_text("from .b import X\nfrom .c import Y\nimport os\n")
    monkeypatch.setattr(registry, "_IMPORTS_MEMO", DiskMemo("imports"))
    assert registry._relative_imports(source, 1, 1) == ("b", "c")

    def no_parse(*args: object, **kwargs: object) -> None:
        raise AssertionError("parsed again")

    # a later process: an empty in-process cache, the memo on disk
    monkeypatch.setattr(registry, "_IMPORTS_MEMO", DiskMemo("imports"))
    monkeypatch.setattr(registry.ast, "parse", no_parse)
    assert registry._relative_imports(source, 2, 2) == ("b", "c")
    source.write_text("from .d import Z\n")  # an edit: a new content hash, parsed
    with pytest.raises(AssertionError, match="parsed again"):
        registry._relative_imports(source, 3, 3)


def test_installed_versions_are_those_of_the_distributions(
    cache: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    from importlib import metadata

    from fmus import disk_memo

    monkeypatch.setattr(disk_memo, "_VERSIONS", DiskMemo("installed-versions"))
    assert disk_memo.installed_version("numpy") == metadata.version("numpy")
    assert disk_memo.installed_version("no_such_package_here") is None
    # a later process: from the memo
    monkeypatch.setattr(disk_memo, "_VERSIONS", DiskMemo("installed-versions"))
    assert disk_memo.installed_version("numpy") == metadata.version("numpy")
    assert any(k.startswith("numpy\x1f") for k in disk_memo._VERSIONS._loaded())


def test_a_file_is_written_whole_or_not_at_all(tmp_path: Path) -> None:
    from fmus.atomic_file import write_whole

    target = tmp_path / "sub" / "f.bin"
    write_whole(target, b"one")
    write_whole(target, b"two")  # over the first
    assert target.read_bytes() == b"two"
    assert target.stat().st_mode & 0o777 == 0o666 & ~_umask()  # not mkstemp's 0600
    with pytest.raises(OSError):
        write_whole(tmp_path / "sub", b"x")  # a folder is there: refused
    assert sorted(p.name for p in (tmp_path / "sub").iterdir()) == ["f.bin"]  # no part left


def _umask() -> int:
    import os

    mask = os.umask(0)
    os.umask(mask)
    return mask
