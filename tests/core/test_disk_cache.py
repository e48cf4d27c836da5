"""engine/disk_cache.py: entries read back bit-exact, keyed by content and code, rebuilt when damaged, bounded,
and a folder that cannot be used leaves the cache off without failing a render."""
import os

import numpy as np
import pytest

from sg_prt_addon.engine import disk_cache


def _arrays():
    rng = np.random.default_rng(3)
    return {"layers": rng.random((2, 4, 4, 3), dtype=np.float32), "sizes": np.arange(5, dtype=np.int64),
            "scale": np.float64(1.5)}


class Builds:
    """A build function that counts its calls."""

    def __init__(self, arrays):
        self.arrays, self.calls = arrays, 0

    def __call__(self):
        self.calls += 1
        return self.arrays


def test_an_entry_is_built_once_and_read_back_bit_exact(tmp_path):
    build = Builds(_arrays())
    first = disk_cache.load_or_build("table", ("name", 1), build, tmp_path)
    again = disk_cache.load_or_build("table", ("name", 1), build, tmp_path)
    assert build.calls == 1
    for name, value in _arrays().items():
        np.testing.assert_array_equal(again[name], value)
        assert again[name].dtype == np.asarray(value).dtype and again[name].shape == np.shape(value)
        np.testing.assert_array_equal(first[name], value)
    assert [path.suffix for path in tmp_path.iterdir()] == [".npz"]          # no temporary file left


def test_other_keys_and_other_code_are_misses(tmp_path, monkeypatch):
    build = Builds(_arrays())
    disk_cache.load_or_build("table", ("name", 1), build, tmp_path)
    disk_cache.load_or_build("table", ("name", 2), build, tmp_path)
    disk_cache.load_or_build("table", (b"\x00\x01",), build, tmp_path)
    disk_cache.load_or_build("environment", ("name", 1), build, tmp_path)
    assert build.calls == 4
    monkeypatch.setattr(disk_cache, "code_digest", lambda: "another version of the add-on")
    disk_cache.load_or_build("table", ("name", 1), build, tmp_path)
    assert build.calls == 5


def test_the_code_digest_changes_with_any_python_source(tmp_path, monkeypatch):
    """An edit to any .py file of the add-on (not only the module that builds an entry) changes the digest;
    other files do not."""
    (tmp_path / "lighting").mkdir()
    (tmp_path / "lighting" / "env_fit.py").write_text("LOBES = 8\n")
    (tmp_path / "registration.py").write_text("")
    monkeypatch.setattr(disk_cache, "_PACKAGE_ROOT", tmp_path)

    def digest():
        disk_cache.code_digest.cache_clear()
        return disk_cache.code_digest()

    try:
        first = digest()
        assert len(first) == 32 and digest() == first
        (tmp_path / "README.md").write_text("notes")
        assert digest() == first
        (tmp_path / "lighting" / "env_fit.py").write_text("LOBES = 9\n")
        assert digest() != first
    finally:
        disk_cache.code_digest.cache_clear()


@pytest.mark.parametrize("damage", ["truncated", "garbage", "empty", "missing member"])
def test_a_damaged_entry_is_rebuilt_and_replaced(tmp_path, damage, capsys):
    build = Builds(_arrays())
    disk_cache.load_or_build("table", ("damaged",), build, tmp_path)
    path = next(tmp_path.glob("*.npz"))
    data = path.read_bytes()
    if damage == "truncated":
        path.write_bytes(data[: len(data) // 2])
    elif damage == "garbage":
        path.write_bytes(data[:100] + bytes(len(data) - 100))        # a zip whose members fail their CRC
    elif damage == "empty":
        path.write_bytes(b"")
    else:
        np.savez(path, other=np.zeros(3))
    rebuilt = disk_cache.load_or_build("table", ("damaged",), build, tmp_path)
    assert build.calls == 2
    np.testing.assert_array_equal(rebuilt["layers"], _arrays()["layers"])
    assert "unreadable" in capsys.readouterr().err
    assert disk_cache._read(path) is not None and "layers" in disk_cache._read(path)


def test_a_folder_that_cannot_be_made_turns_the_cache_off(tmp_path, monkeypatch):
    blocker = tmp_path / "a file"
    blocker.write_text("not a folder")
    monkeypatch.setenv(disk_cache.DIRECTORY_VARIABLE, str(blocker / "cache"))
    assert disk_cache.directory() is None
    build = Builds(_arrays())
    assert disk_cache.load_or_build("table", ("x",), build)["sizes"].tolist() == [0, 1, 2, 3, 4]
    monkeypatch.setenv(disk_cache.DIRECTORY_VARIABLE, "")
    assert disk_cache.directory() is None


def test_without_the_variable_the_cache_is_the_users(monkeypatch, tmp_path):
    monkeypatch.delenv(disk_cache.DIRECTORY_VARIABLE, raising=False)
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))
    assert disk_cache.directory() == tmp_path / "sg-prt"


def test_pruning_drops_the_least_recently_used_first(tmp_path):
    paths = []
    for index in range(4):
        disk_cache.load_or_build("table", (index,), lambda: {"a": np.zeros(1000)}, tmp_path)
        path = tmp_path / disk_cache.entry_name("table", (index,))
        os.utime(path, (1000 + index, 1000 + index))
        paths.append(path)
    disk_cache.load_or_build("table", (0,), lambda: pytest.fail("entry 0 was there"), tmp_path)   # used: newest
    size = paths[0].stat().st_size
    disk_cache.prune(tmp_path, max_bytes=2 * size)
    assert [path.exists() for path in paths] == [True, False, False, True]
