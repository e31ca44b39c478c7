"""Where gmuk's numba kernels are cached (gmuk._numba): beside the sources when that folder is
writable, else in a user cache folder, never against the user's NUMBA_CACHE_DIR.

A folder is made unwritable for everyone, root included, by putting a regular file where
numba would create its ``__pycache__`` folder (the test suite may run as root, for whom
permission bits do not stop a write).
"""

from __future__ import annotations

import ast
import inspect
import os
import subprocess
import sys
import textwrap
from pathlib import Path

import numba

import gmuk._numba as gn
from gmuk._numba import cache_plan, njit, user_cache_dir


def _unwritable_source_dir(tmp_path: Path) -> Path:
    src = tmp_path / "src"
    src.mkdir()
    (src / "__pycache__").write_text("a file where numba would make its cache folder\n")
    return src


def test_user_cache_dir_posix():
    home = {"HOME": "/home/ann"}
    assert user_cache_dir(home, windows=False) == Path("/home/ann/.cache/gmuk/numba")
    xdg = {**home, "XDG_CACHE_HOME": "/var/cache/ann"}
    assert user_cache_dir(xdg, windows=False) == Path("/var/cache/ann/gmuk/numba")
    relative = {**home, "XDG_CACHE_HOME": "cache"}  # not absolute: ignored (XDG spec)
    assert user_cache_dir(relative, windows=False) == Path("/home/ann/.cache/gmuk/numba")
    empty = {**home, "XDG_CACHE_HOME": ""}
    assert user_cache_dir(empty, windows=False) == Path("/home/ann/.cache/gmuk/numba")
    assert user_cache_dir({}, windows=False) == Path.home() / ".cache" / "gmuk" / "numba"


def test_user_cache_dir_windows():
    env = {"LOCALAPPDATA": r"C:\Users\ann\AppData\Local", "XDG_CACHE_HOME": "/ignored"}
    assert user_cache_dir(env, windows=True) == Path(env["LOCALAPPDATA"]) / "gmuk" / "numba"
    assert user_cache_dir({}, windows=True) == Path.home() / "AppData" / "Local" / "gmuk" / "numba"


def test_writable_source_folder_keeps_numbas_choice(tmp_path):
    env = {"XDG_CACHE_HOME": str(tmp_path / "xdg")}
    assert cache_plan(tmp_path, environ=env, windows=False) == (True, "")
    assert (tmp_path / "__pycache__").is_dir()  # what numba itself would make
    assert not (tmp_path / "xdg").exists()


def test_unwritable_source_folder_goes_to_the_user_cache_folder(tmp_path):
    src = _unwritable_source_dir(tmp_path)
    env = {"XDG_CACHE_HOME": str(tmp_path / "xdg"), "HOME": str(tmp_path / "home")}
    cache, where = cache_plan(src, environ=env, windows=False)
    assert cache and Path(where) == tmp_path / "xdg" / "gmuk" / "numba"
    assert Path(where).is_dir()
    cache, where = cache_plan(src, environ={"HOME": str(tmp_path / "home")}, windows=False)
    assert cache and Path(where) == tmp_path / "home" / ".cache" / "gmuk" / "numba"


def test_configured_cache_folder_is_left_alone(tmp_path):
    src = _unwritable_source_dir(tmp_path)
    env = {"XDG_CACHE_HOME": str(tmp_path / "xdg")}
    assert cache_plan(src, configured="/somewhere", environ=env, windows=False) == (True, "")
    assert not (tmp_path / "xdg").exists()


def test_nothing_writable_compiles_without_cache(tmp_path):
    src = _unwritable_source_dir(tmp_path)
    blocker = tmp_path / "not-a-folder"
    blocker.write_text("")
    env = {"XDG_CACHE_HOME": str(blocker)}  # the user cache folder would be inside a file
    assert cache_plan(src, environ=env, windows=False) == (False, "")


def test_cache_dir_is_set_only_while_decorating(tmp_path, monkeypatch):
    before = numba.config.CACHE_DIR
    seen = []

    def plan(source_dir, configured):
        seen.append((source_dir, configured))
        return True, str(tmp_path / "kernels")

    monkeypatch.setattr(gn, "_plan_for", plan)

    def add_one(x):
        return x + 1

    kernel = njit(cache=True)(add_one)
    assert numba.config.CACHE_DIR == before  # restored
    assert seen == [(str(Path(inspect.getfile(add_one)).parent), str(before or ""))]
    assert kernel.stats.cache_path.startswith(str(tmp_path / "kernels"))
    assert kernel(41) == 42
    assert list((Path(kernel.stats.cache_path)).glob("*add_one*.nbi"))
    # kernels without cache=True never consult the plan
    assert njit(lambda x: x * 2)(4) == 8 and len(seen) == 1


def test_no_writable_folder_means_no_cache(monkeypatch):
    monkeypatch.setattr(gn, "_plan_for", lambda source_dir, configured: (False, ""))

    def add_two(x):
        return x + 2

    kernel = njit("int64(int64)", cache=True)(add_two)
    assert kernel(40) == 42
    assert kernel.stats.cache_path is None  # numba's cache of a function without one


_KERNEL_MODULE = """
from gmuk._numba import njit

@njit("float64(float64)", cache=True)
def triple(x):
    return 3.0 * x
"""

_RUN = """
import sys
sys.path.insert(0, {src!r})
import kern
assert kern.triple(2.0) == 6.0
print(sum(kern.triple.stats.cache_hits.values()), kern.triple.stats.cache_path)
"""


def _run(src: Path, env: dict[str, str]) -> tuple[int, Path]:
    out = subprocess.run(
        [sys.executable, "-c", _RUN.format(src=str(src))],
        env=env,
        capture_output=True,
        text=True,
        timeout=600,
        check=True,
    ).stdout.split()
    return int(out[-2]), Path(out[-1])


def _env(tmp_path: Path, **extra: str) -> dict[str, str]:
    env = {k: v for k, v in os.environ.items() if k != "NUMBA_CACHE_DIR"}
    env.update(XDG_CACHE_HOME=str(tmp_path / "xdg"), HOME=str(tmp_path / "home"), **extra)
    return env


_DECORATORS = {"njit", "jit", "generated_jit", "vectorize", "guvectorize", "cfunc"}


def test_fresh_process_caches_in_the_user_folder_and_loads_from_it(tmp_path):
    src = _unwritable_source_dir(tmp_path)
    (src / "kern.py").write_text(textwrap.dedent(_KERNEL_MODULE))
    env = _env(tmp_path)
    hits, where = _run(src, env)
    assert hits == 0 and where.parent == tmp_path / "xdg" / "gmuk" / "numba"
    assert list(where.glob("kern.triple-*.nbi")) and list(where.glob("kern.triple-*.nbc"))
    assert not (tmp_path / "xdg" / "numba").exists()  # not numba's own fallback folder
    hits, again = _run(src, env)
    assert hits == 1 and again == where  # the second process loads the compiled kernel


def test_fresh_process_respects_numba_cache_dir(tmp_path):
    src = _unwritable_source_dir(tmp_path)
    (src / "kern.py").write_text(textwrap.dedent(_KERNEL_MODULE))
    mine = tmp_path / "mine"
    env = _env(tmp_path, NUMBA_CACHE_DIR=str(mine))
    hits, where = _run(src, env)
    assert hits == 0 and where.parent == mine
    assert not (tmp_path / "xdg").exists()


def test_every_gmuk_kernel_is_decorated_through_gmuk_numba():
    # A kernel decorated with numba's own njit or jit would miss the cache placement.
    root = Path(gn.__file__).resolve().parent
    offenders = []
    for path in sorted(root.rglob("*.py")):
        if path.name == "_numba.py":
            continue
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.ImportFrom) and (node.module or "").startswith("numba"):
                offenders += [
                    f"{path}: from {node.module} import {a.name}"
                    for a in node.names
                    if a.name in _DECORATORS
                ]
            elif isinstance(node, ast.Attribute) and node.attr in _DECORATORS:
                if isinstance(node.value, ast.Name) and node.value.id == "numba":
                    offenders.append(f"{path}:{node.lineno}: numba.{node.attr}")
    assert not offenders
    kernel_modules = {"_validation", "_uk_kernels", "_kernels", "legendre"}
    users = {
        p.stem for p in root.rglob("*.py") if "from gmuk._numba import" in p.read_text("utf-8")
    }
    assert kernel_modules <= users
