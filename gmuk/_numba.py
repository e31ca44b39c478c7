"""numba for gmuk's kernels: where their compiled code is cached, and calls without dispatch.

Cache location
--------------
gmuk's kernels are compiled with ``cache=True`` through :func:`njit`, which is
:func:`numba.njit` with one addition: where the cache goes. numba keeps a function's cache
in the ``__pycache__`` folder beside its source file when it can write there. When it cannot
(an installation owned by another user, a read-only file system or image), gmuk's kernels
are cached in a user cache folder instead:

* POSIX: ``$XDG_CACHE_HOME/gmuk/numba``, or ``~/.cache/gmuk/numba`` when ``XDG_CACHE_HOME`` is
  unset or not an absolute path (as the XDG specification asks);
* Windows: ``%LOCALAPPDATA%\\gmuk\\numba``.

A cache folder the user chose (``NUMBA_CACHE_DIR``, read by numba into
``numba.config.CACHE_DIR``) is always left as it is. If neither the source folder nor the
user cache folder is writable, the kernels are compiled without a cache (each process
compiles them again) instead of failing to import.

numba fixes a function's cache folder when the decorator runs (it builds the cache locator
then; compilation and later loads use that folder). :func:`njit` therefore decides per
kernel at decoration time and, when the user cache folder is needed, sets
``numba.config.CACHE_DIR`` for the duration of the decoration only. The environment and the
cache location of every other numba user in the process are left alone, and the import
order of numba and gmuk does not matter.

Damaged cache files
-------------------
A cache file that cannot be read (truncated by a full disk or a killed process, or written
by a numba whose format differs) is not an error: :func:`njit` gives each cached kernel a
cache that treats such a file as a miss, removes its index (a :class:`GmukWarning` names it)
and compiles the kernel again, which writes a fresh one.

Kernels that call kernels of other modules
------------------------------------------
numba checks a cached kernel against its own source file only, yet a kernel's compiled code
contains every kernel it calls, from any module: the compiled step loop holds the force,
constraint, controller and solve kernels. :func:`sources_key` is a digest of every gmuk source
that defines a kernel. Each cache folder of gmuk's kernels records the digest it was written
under (``gmuk-kernels.key``); the first time a process looks up a kernel in a folder whose
digest differs (a kernel edited anywhere, in a development install), the folder's cache
indexes are removed before anything is loaded from it (:func:`check_cache_folder`), and the
kernels compile again and write new ones.

Kernels called through their address
-------------------------------------
The compiled step loop does not contain the parts' kernels: it calls each through the address
of its compiled function (:func:`kernel_address`), with :func:`kernel_caller`, in numba's own
calling convention, so that an exception a kernel raises reaches the caller as it would from
a direct call. A kernel is then compiled (or loaded from the cache) only when a System uses
it, and neither the loop's compiled code nor its compile time grows with the number of parts
gmuk or a plugin defines. Each kind of part fixes its kernels' signature (the argument types
the loop passes, :data:`gmuk.forces.base.FORCE_KERNEL` and its kin); the caller checks the
argument types against it when the loop compiles, and :func:`kernel_address` compiles the
kernel for exactly that signature.

Calling without the dispatcher
------------------------------
numba's dispatcher resolves the types of a kernel's arguments on every call, which costs
more than the arithmetic of a small kernel and grows with the number of arguments.
:func:`entry` returns the compiled function of a kernel that has one explicit signature; it
skips that resolution and checks nothing beyond the Python type of each argument: arrays
must be exactly the declared types (dtype, number of dimensions, C-contiguity), or the
kernel reads memory wrongly. Callers check that before taking such a path.
"""

from __future__ import annotations

import functools
import hashlib
import inspect
import os
import sys
import tempfile
import warnings
from collections.abc import Callable, Iterator, Mapping
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import numba
from numba import types
from numba.core import cgutils
from numba.core.caching import FunctionCache
from numba.core.errors import TypingError
from numba.extending import intrinsic

from gmuk.errors import GmukWarning

__all__ = [
    "C1",
    "C1_READONLY",
    "C2",
    "LazyEntries",
    "cache_plan",
    "check_cache_folder",
    "compiled_entry",
    "entry",
    "kernel_address",
    "kernel_caller",
    "njit",
    "sources_key",
    "user_cache_dir",
]

#: The array types of the parts' kernel signatures: C-contiguous float64, 1-D, 2-D and
#: read-only 1-D (a spherical-harmonic field's data, shared by every term of a program).
C1 = types.Array(types.float64, 1, "C")
C2 = types.Array(types.float64, 2, "C")
C1_READONLY = types.Array(types.float64, 1, "C", readonly=True)

#: numba's configuration module (its settings are attributes made at run time).
_config: Any = numba.config


def user_cache_dir(
    environ: Mapping[str, str] | None = None, *, windows: bool | None = None
) -> Path:
    """The user cache folder for gmuk's compiled kernels (see the module docstring).

    Parameters
    ----------
    environ : mapping, optional
        Environment variables to read (default ``os.environ``).
    windows : bool, optional
        Use the Windows convention (default: whether this is Windows).
    """
    env = os.environ if environ is None else environ
    if windows is None:
        windows = sys.platform == "win32"
    if windows:
        base = env.get("LOCALAPPDATA")
        root = Path(base) if base else Path.home() / "AppData" / "Local"
        return root / "gmuk" / "numba"
    xdg = env.get("XDG_CACHE_HOME", "")
    if xdg and os.path.isabs(xdg):
        return Path(xdg) / "gmuk" / "numba"
    home = env.get("HOME")
    return (Path(home) if home else Path.home()) / ".cache" / "gmuk" / "numba"


def _writable(folder: Path) -> bool:
    """Whether ``folder`` exists or can be made, and a file can be created in it: the test
    numba applies to a cache folder before it uses one."""
    try:
        os.makedirs(folder, exist_ok=True)
        tempfile.TemporaryFile(dir=folder).close()
    except OSError:
        return False
    return True


def cache_plan(
    source_dir: str | os.PathLike[str],
    *,
    configured: str = "",
    environ: Mapping[str, str] | None = None,
    windows: bool | None = None,
) -> tuple[bool, str]:
    """Whether to cache the kernels of one source folder, and where.

    Parameters
    ----------
    source_dir : path-like
        Folder of the kernels' source file; numba's own cache would be its ``__pycache__``.
    configured : str
        The cache folder configured for numba (``numba.config.CACHE_DIR``; empty if none).
    environ, windows
        As for :func:`user_cache_dir`.

    Returns
    -------
    cache : bool
        ``False`` only if no cache folder is writable.
    directory : str
        The folder to set as numba's cache folder while the kernel is decorated, or ``""``
        to leave numba's choice alone: the configured folder, or ``__pycache__`` beside the
        source when it is writable.
    """
    if configured or _writable(Path(source_dir) / "__pycache__"):
        return True, ""
    folder = user_cache_dir(environ, windows=windows)
    if _writable(folder):
        return True, str(folder)
    return False, ""


@functools.cache
def _plan_for(source_dir: str, configured: str) -> tuple[bool, str]:
    return cache_plan(source_dir, configured=configured)


@contextmanager
def _cache_dir(directory: str) -> Iterator[None]:
    """numba's cache folder set to ``directory`` inside the block (unchanged if empty)."""
    if not directory:
        yield
        return
    before = _config.CACHE_DIR
    _config.CACHE_DIR = directory
    try:
        yield
    finally:
        _config.CACHE_DIR = before


class _CheckedCache(FunctionCache):
    """numba's function cache, with an unreadable cache file taken as a miss: the file's
    index is removed (so that the next save writes a fresh one) and the kernel compiles."""

    def load_overload(self, sig: Any, target_context: Any) -> Any:
        folder = getattr(self, "_cache_path", None)
        if folder:
            check_cache_folder(Path(folder))
        try:
            return super().load_overload(sig, target_context)
        except Exception as exc:  # a damaged or foreign file: pickle, EOF, OS errors …
            self._discard(exc)
            return None

    def save_overload(self, sig: Any, data: Any) -> None:
        try:
            super().save_overload(sig, data)
        except Exception as exc:  # the index it appends to is damaged: start a new one
            self._discard(exc)
            with _suppressed():
                super().save_overload(sig, data)

    def _discard(self, exc: Exception) -> None:
        index = getattr(getattr(self, "_cache_file", None), "_index_path", None)
        if index is None:
            return
        warnings.warn(
            f"gmuk: a damaged numba cache file ({index}: {type(exc).__name__}) was removed; "
            "the kernel is compiled again",
            GmukWarning,
            stacklevel=2,
        )
        with _suppressed():
            os.unlink(index)


@contextmanager
def _suppressed() -> Iterator[None]:
    """Ignore any error inside (a cache that cannot be written is no reason to fail)."""
    try:
        yield
    except Exception:  # the kernel runs uncached
        pass


def _checked(dispatcher: Any) -> Any:
    """``dispatcher`` with its numba cache replaced by :class:`_CheckedCache`."""
    if type(getattr(dispatcher, "_cache", None)) is FunctionCache:
        dispatcher._cache.__class__ = _CheckedCache
    return dispatcher


def _kernel_sources() -> list[Path]:
    """gmuk's source files that define numba kernels, in a fixed order."""
    root = Path(__file__).resolve().parent
    return sorted(p for p in root.rglob("*.py") if "njit(" in p.read_text(encoding="utf-8"))


@functools.cache
def sources_key() -> str:
    """A digest of every gmuk source that defines a kernel, and of numba's version."""
    root = Path(__file__).resolve().parent
    digest = hashlib.sha256(numba.__version__.encode())
    for path in _kernel_sources():
        digest.update(str(path.relative_to(root)).encode())
        digest.update(path.read_bytes())
    return digest.hexdigest()


_CHECKED_FOLDERS: set[Path] = set()


def check_cache_folder(folder: Path) -> bool:
    """Remove the cache indexes in ``folder`` (one of gmuk's kernel cache folders) unless it
    records :func:`sources_key`, and record the key; once per folder and process, before the
    first lookup there. Returns whether indexes were removed."""
    if folder in _CHECKED_FOLDERS:
        return False
    _CHECKED_FOLDERS.add(folder)
    key = sources_key()
    key_file = folder / "gmuk-kernels.key"
    try:
        if key_file.read_text(encoding="ascii") == key:
            return False
    except (OSError, UnicodeDecodeError):
        pass
    removed = False
    with _suppressed():
        for index in folder.glob("*.nbi"):
            os.unlink(index)
            removed = True
    with _suppressed():
        folder.mkdir(parents=True, exist_ok=True)
        key_file.write_text(key, encoding="ascii")
    return removed


def njit(*args: Any, **options: Any) -> Any:
    """:func:`numba.njit`, with the cache of ``cache=True`` kernels placed as described in the
    module docstring.

    Takes numba's arguments and is used the same ways: ``@njit(signature, cache=True)``,
    ``@njit(cache=True)``, ``njit(cache=True)(function)``.
    """
    if args and inspect.isfunction(args[0]):  # bare @njit
        return njit(*args[1:], **options)(args[0])

    def decorate(func: Callable[..., Any]) -> Any:
        if not options.get("cache"):
            return numba.njit(*args, **options)(func)
        configured = str(_config.CACHE_DIR or "")
        cache, directory = _plan_for(str(Path(inspect.getfile(func)).parent), configured)
        with _cache_dir(directory):
            return _checked(numba.njit(*args, **{**options, "cache": cache})(func))

    return decorate


def entry(kernel: Any) -> Any:
    """The compiled function of a single-signature kernel, callable without dispatch.

    Falls back to the dispatcher itself (safe, slower) if numba does not expose the
    compiled function or the kernel has more than one signature.
    """
    overloads = list(getattr(kernel, "overloads", {}).values())
    if len(overloads) == 1:
        fn = getattr(overloads[0], "entry_point", None)
        if callable(fn):
            return fn
    return kernel


def overload_entry(kernel: Any, signature: Any) -> Any:
    """The compiled function of ``kernel``'s overload for ``signature``, callable without
    dispatch: compiled now (or loaded from numba's cache) unless it exists already. The
    dispatcher stays open to other types (unlike :func:`compiled_entry`)."""
    kernel.compile(signature)  # the existing overload when there is one
    return kernel.overloads[signature.args].entry_point


def compiled_entry(kernel: Any, signature: Any) -> Any:
    """Compile ``kernel`` (a dispatcher made without a signature) for ``signature`` only — or
    load it from numba's cache — close it to further compilation, as a signature given to
    the decorator would, and return its :func:`entry`."""
    if not kernel.overloads:
        kernel.compile(signature)
        kernel.disable_compile()
    return entry(kernel)


class LazyEntries:
    """Entry points of single-signature kernels, each compiled (or loaded from numba's
    cache) the first time it is used, not when its module is imported.

    ``LazyEntries(name=(kernel, signature), ...)``; ``entries.name`` is then the compiled
    entry (:func:`compiled_entry`), kept as an ordinary attribute after the first access.
    A kernel given a signature in its decorator compiles at import: a process that never
    calls it (a run without spherical harmonics) would pay for it all the same.
    """

    def __init__(self, **kernels: tuple[Any, Any]) -> None:
        self._pending = dict(kernels)

    def __getattr__(self, name: str) -> Any:  # only for names not yet resolved
        try:
            kernel, signature = self.__dict__["_pending"][name]
        except KeyError:
            raise AttributeError(name) from None
        fn = compiled_entry(kernel, signature)
        setattr(self, name, fn)
        return fn


def kernel_address(kernel: Any, signature: Any) -> int:
    """The address of ``kernel``'s compiled function for ``signature``, compiled now or loaded
    from numba's cache: what :func:`kernel_caller`'s intrinsic calls.

    Parameters
    ----------
    kernel : numba dispatcher
        A kernel made with :func:`njit` without a signature.
    signature : numba signature
        The signature of the kind of part (return type included).

    Raises
    ------
    DefinitionError
        When the kernel does not compile for ``signature`` or returns another type.
    """
    from gmuk.errors import DefinitionError

    known = _ADDRESSES.get((id(kernel), id(signature)))
    if known is not None and known[0] is kernel and known[1] is signature:
        return known[2]
    name = getattr(kernel, "__qualname__", repr(kernel))
    try:
        if signature.args not in kernel.overloads:
            kernel.compile(signature)
        cres = kernel.overloads[signature.args]
    except Exception as exc:  # numba's typing and lowering errors
        raise DefinitionError(
            f"kernel {name} does not compile for the signature {signature}: {exc}"
        ) from exc
    if types.unliteral(cres.signature.return_type) != signature.return_type:
        raise DefinitionError(
            f"kernel {name} returns {cres.signature.return_type}; its kind of part asks for "
            f"{signature.return_type}"
        )
    address = int(cres.library.get_pointer_to_function(cres.fndesc.llvm_func_name))
    # the objects themselves are kept with the address, so that an id reused after one of
    # them is gone cannot match: compiled code stays loaded for the process
    _ADDRESSES[(id(kernel), id(signature))] = (kernel, signature, address)
    return address


#: kernel_address's answers, by the ids of the kernel and the signature (numba's types hash
#: slowly, and a run packs the address of each of its parts)
_ADDRESSES: dict[tuple[int, int], tuple[Any, Any, int]] = {}


def kernel_caller(signature: Any, kind: str) -> Any:
    """An intrinsic ``call(address, args)`` that calls the kernel at ``address`` (from
    :func:`kernel_address` with the same ``signature``) with the tuple ``args`` and returns
    its result; an exception the kernel raises propagates to the caller.

    The argument types must be exactly ``signature.args``: the caller's compilation fails
    otherwise (a kernel given other types would read its arguments wrongly). ``kind`` names
    the kind of part in that error.
    """
    expected = tuple(signature.args)

    def call(typingctx, address, args):  # type: ignore[no-untyped-def]
        if not isinstance(address, types.Integer) or not isinstance(args, types.BaseTuple):
            return None
        if tuple(args.types) != expected:
            raise TypingError(
                f"a {kind} kernel takes {expected}; the caller passes {tuple(args.types)}"
            )

        def codegen(context, builder, sig, llargs):  # type: ignore[no-untyped-def]
            conv = context.call_conv
            fnty = conv.get_function_type(signature.return_type, expected)
            fn = builder.inttoptr(llargs[0], fnty.as_pointer())
            ret = cgutils.alloca_once(builder, fnty.args[0].pointee)
            builder.store(cgutils.get_null_value(fnty.args[0].pointee), ret)
            excinfo = cgutils.alloca_once(builder, fnty.args[1].pointee, name="excinfo")
            values = [builder.extract_value(llargs[1], i) for i in range(len(expected))]
            packed = list(conv._get_arg_packer(expected).as_arguments(builder, values))
            code = builder.call(fn, [ret, excinfo, *packed])
            status = conv._get_return_status(builder, code, builder.load(excinfo))
            with cgutils.if_unlikely(builder, status.is_error):
                conv.return_status_propagate(builder, status)
            return builder.load(ret)

        return signature.return_type(address, args), codegen

    call.__name__ = call.__qualname__ = f"call_{kind.replace(' ', '_')}_kernel"
    return intrinsic(call)


def _holds_arrays(ty: Any) -> bool:
    """Whether a numba type is an array or a tuple (or named tuple) holding one."""
    if isinstance(ty, types.Array):
        return True
    return isinstance(ty, types.BaseTuple) and any(_holds_arrays(t) for t in _members(ty))


def _members(ty: Any) -> tuple[Any, ...]:
    """The member types of a numba tuple or named tuple type."""
    return tuple(ty.types)


def _borrow_value(context: Any, builder: Any, ty: Any, value: Any) -> Any:
    """The LLVM value of type ``ty`` with every array in it (itself, or the members of a
    tuple, recursively) rebuilt with no memory owner."""
    if isinstance(ty, types.Array):
        src = context.make_array(ty)(context, builder, value=value)
        out = context.make_array(ty)(context, builder)
        context.populate_array(
            out,
            data=src.data,
            shape=src.shape,
            strides=src.strides,
            itemsize=src.itemsize,
            meminfo=None,
        )
        return out._getvalue()
    for i, member in enumerate(_members(ty)):
        if _holds_arrays(member):
            item = builder.extract_value(value, i)
            value = builder.insert_value(value, _borrow_value(context, builder, member, item), i)
    return value


def _borrowed(typingctx, array):  # type: ignore[no-untyped-def]
    """``array`` as a borrowed reference: the same data, shape and strides with no memory
    owner, so that the views taken of it (``a[i]``, ``a[i:j]``) and the calls it is passed to
    skip the atomic reference counting of numba's runtime. Each increment and decrement is a
    locked instruction, and the row kernels and the tree solve take views in their inner
    loops: counting them was half the time of a robot's evaluation. A tuple or named tuple
    (the compiled loop's records) comes back with each array in it borrowed: a call counts
    every array of a record it is handed, on entry and on exit.

    Only for an array that outlives every use of the result, as a function's argument does
    during the call (its caller holds it): a borrowed array must not be returned, stored in
    a container or given to Python, which would hold memory no one owns."""
    if not _holds_arrays(array):
        return None

    def codegen(context, builder, sig, args):  # type: ignore[no-untyped-def]
        return _borrow_value(context, builder, sig.args[0], args[0])

    return array(array), codegen


#: :func:`_borrowed` as the intrinsic the kernels call: ``borrowed(array)``.
borrowed: Any = intrinsic(_borrowed)
