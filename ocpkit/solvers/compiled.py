"""CasADi Functions, and other C, compiled once per machine.

`compiled(functions)` generates their C (casadi.CodeGenerator), compiles it with the system C compiler ($CC, else
`cc`) into a shared library kept in a disk cache named by the hash of the C, the compiler and its flags
(~/.cache/ocpkit/compiled, or $XDG_CACHE_HOME/ocpkit/compiled; $OCPKIT_COMPILED_DIR overrides), and loads it
with casadi.external: the same values as CasADi's virtual machine, evaluated faster (figures: docs/design-notes.md).
A library is written under a temporary name and renamed into place, so processes compiling the same C at once do
not clash.
Without a compiler, or when a compile or the loading fails, there is nothing to load: None, with one warning.
`shared_library(source)` is the same cache for C written by hand (ocpkit.solvers.chain: the path search's collision
test, the collision rows' derivatives).
"""

from __future__ import annotations

import hashlib
import os
import shutil
import subprocess
import tempfile
import time
import warnings
from collections.abc import Sequence
from pathlib import Path

import casadi as ca

FLAGS = ("-O1", "-fPIC", "-shared")
"""-O1: optimized code for a short compile; -O2 and -O3 compile longer for little faster code (figures:
docs/design-notes.md)."""
_warned: set[str] = set()
_spent = 0.0  # seconds this process has spent compiling


def compile_seconds() -> float:
    """Seconds this process has spent compiling so far (the set-up's `compile` part: ocpkit.planner.build_cache)."""
    return _spent


def cache_directory() -> Path:
    """Where compiled libraries are kept (module docstring)."""
    if os.environ.get("OCPKIT_COMPILED_DIR"):
        return Path(os.environ["OCPKIT_COMPILED_DIR"])
    return Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache") / "ocpkit" / "compiled"


def compiler() -> str | None:
    """The C compiler's path ($CC, else `cc`), or None when there is none."""
    return shutil.which(os.environ.get("CC") or "cc")


def compiled(functions: Sequence[ca.Function]) -> list[ca.Function] | None:
    """`functions` (distinct names) compiled to C and loaded from the disk cache, compiling on a miss; None when
    they cannot be compiled (module docstring)."""
    generator = ca.CodeGenerator("ocpkit_compiled.c", {"with_header": False})
    for function in functions:
        generator.add(function)
    library = shared_library(generator.dump())
    if library is None:
        return None
    try:
        return [ca.external(function.name(), str(library)) for function in functions]
    except RuntimeError as exc:  # e.g. a library damaged on disk
        return _unavailable(f"cannot load {library} (delete it to compile afresh): "
                            f"{str(exc).strip().splitlines()[-1]}")


def shared_library(source: str, flags: Sequence[str] = FLAGS) -> Path | None:
    """The shared library of the C `source` compiled with `flags`, from the disk cache, compiling on a miss; None
    (with one warning) without a compiler or when the compile fails."""
    cc = compiler()
    if cc is None:
        return _unavailable("no C compiler found (install gcc, or set CC)")
    digest = hashlib.sha256("\0".join([source, Path(cc).name, *flags]).encode()).hexdigest()[:24]
    library = cache_directory() / f"{digest}.so"
    if not library.exists():
        try:
            _compile(cc, source, library, flags)
        except (OSError, subprocess.CalledProcessError) as exc:
            detail = exc.stderr.decode(errors="replace").strip()[-300:] if getattr(exc, "stderr", None) else exc
            return _unavailable(f"compiling to {library} failed: {detail}")
    return library


def _compile(cc: str, source: str, library: Path, flags: Sequence[str]) -> None:
    """Compile `source` into `library`, written under a temporary name and renamed into place."""
    global _spent
    began = time.perf_counter()
    library.parent.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(dir=library.parent) as work:
        c_file, built = Path(work) / "functions.c", Path(work) / "functions.so"
        c_file.write_text(source)
        subprocess.run([cc, *flags, str(c_file), "-o", str(built)], check=True, capture_output=True)
        os.replace(built, library)
    _spent += time.perf_counter() - began


def _unavailable(reason: str) -> None:
    """None, with a warning (once per reason) that slower code computes the same values instead."""
    if reason not in _warned:
        _warned.add(reason)
        warnings.warn(f"{reason}; slower code computes the same values instead (CasADi's virtual machine; coal for "
                      "the path search's collision test)", stacklevel=3)
