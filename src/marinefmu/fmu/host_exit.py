"""Process exit of a host that has loaded a pythonfmu 0.7.0 FMU library (Linux).

Each FMU carries its own copy of pythonfmu's native library (``binaries/linux64/<Model>.so``),
and each copy holds the embedded interpreter's keeper in a namespace-scope
``std::shared_ptr<PyState> pyState``. At ``exit()`` two clean-ups of that pointer run, in this
order, for every copy still loaded:

1. the C++ static destructor of ``pyState``, an exit handler the library registered with
   ``__cxa_atexit`` when it was loaded: it destroys the ``PyState`` and frees the 128-byte block
   ``std::make_shared`` allocated in ``pythonfmu::createInstance``;
2. the loader's finalisation of the library (``_dl_fini``), which calls its
   ``__attribute__((destructor)) onLibraryUnload()``, which calls the exported
   ``finalizePythonInterpreter()``: ``pyState = nullptr``. The destroyed pointer still holds the
   freed block's address, so the assignment decrements a reference count inside freed memory
   (``lock xadd`` at offset 8). Whether that later aborts the process (``corrupted
   double-linked list`` in an unrelated ``free``) depends on the heap's layout at that moment.

When a host unloads the library itself (``dlclose``) the order is the reverse (the library's
destructor first, then its static destructors), and nothing is wrong.

:func:`guard` makes the exit take the ``dlclose`` order: at the first instantiation of each
loaded copy it registers that copy's ``finalizePythonInterpreter`` as one more ``__cxa_atexit``
handler, under the library's own DSO handle (``__dso_handle``, read from the file's symbol
table). Exit handlers run in the reverse order of registration, so this one runs before the
static destructor: it empties ``pyState`` while the block is alive (destroying the ``PyState``
as pythonfmu designed), and the two later clean-ups find an empty pointer. Registered under the
library's handle, it is also run, and discarded, by the library's own ``__cxa_finalize`` when a
host unloads the library, so no handler outlives the code it points to.

What ``finalizePythonInterpreter`` does there depends on who started the interpreter, and is
right in both cases, so the guard does not need to know which host it is in:

- a Python host (FMPy, libcosimpy, pytest, a Dask worker): the interpreter was running when the
  first instance made the ``PyState``, so its thread ended at once and its destructor only joins
  that ended thread; the host's interpreter is not touched (the host finalises it before
  ``exit()`` runs the C handlers);
- a host that is not Python: ``PyState``'s thread started the interpreter and is waiting to
  finalise it; the guard lets it do so a few exit handlers earlier than the static destructor
  would have, with no Python code of the guard running at that point.

A guard is registered once per loaded copy: with it, a semaphore that a second handler posts
when the pair runs, so a copy that was unloaded (the pair ran in its ``__cxa_finalize``) and
loaded again is guarded again. The semaphore is allocated with ``calloc`` and never freed: it
is written during ``exit()``, after the interpreter is gone. A guard registered twice (two
threads instantiating at once) is harmless: the second call finds ``pyState`` empty.

Windows needs nothing: pythonfmu's ``DllMain`` is in an unnamed namespace, so it is not the
DLL's entry point and ``finalizePythonInterpreter`` is never called by the library; only the
static destructor runs (read from the source and the 0.7.0 DLL, not run). Other platforms have
no pythonfmu binaries. See docs/fmu_contract.md, "Process exit", and the decision record
docs/decisions/fmu-exit-use-after-free.md (the valgrind trace, the measurements).
"""
from __future__ import annotations

import ctypes
import os
import struct
import sys
from pathlib import Path

FINALIZE = "finalizePythonInterpreter"
DSO_HANDLE = "__dso_handle"
_SEM_T_BYTES = 32               # sizeof(sem_t) on 64-bit Linux (16 on 32-bit)

#: Semaphore (its address) of the guard of each loaded library copy, by the copy's __dso_handle address.
_GUARDS: dict[int, int] = {}
#: Offsets (finalizePythonInterpreter, __dso_handle) in each library file, by (device, inode, mtime).
_SYMBOLS: dict[tuple[int, int, int], tuple[int, int] | None] = {}
_libc: ctypes.CDLL | None = None


class _DlInfo(ctypes.Structure):
    _fields_ = [("dli_fname", ctypes.c_char_p), ("dli_fbase", ctypes.c_void_p),
                ("dli_sname", ctypes.c_char_p), ("dli_saddr", ctypes.c_void_p)]


def _c() -> ctypes.CDLL:
    """The C library's loader, exit-handler and semaphore functions (process-wide names)."""
    global _libc
    if _libc is None:
        libc = ctypes.CDLL(None)
        for name, args, res in (
                ("dlopen", [ctypes.c_char_p, ctypes.c_int], ctypes.c_void_p),
                ("dlsym", [ctypes.c_void_p, ctypes.c_char_p], ctypes.c_void_p),
                ("dlclose", [ctypes.c_void_p], ctypes.c_int),
                ("dladdr", [ctypes.c_void_p, ctypes.POINTER(_DlInfo)], ctypes.c_int),
                ("__cxa_atexit", [ctypes.c_void_p, ctypes.c_void_p, ctypes.c_void_p], ctypes.c_int),
                ("calloc", [ctypes.c_size_t, ctypes.c_size_t], ctypes.c_void_p),
                ("sem_init", [ctypes.c_void_p, ctypes.c_int, ctypes.c_uint], ctypes.c_int),
                ("sem_getvalue", [ctypes.c_void_p, ctypes.POINTER(ctypes.c_int)], ctypes.c_int)):
            fn = getattr(libc, name)
            fn.argtypes, fn.restype = args, res
        _libc = libc
    return _libc


def elf_symbols(path: Path) -> dict[str, int]:
    """Values of ``finalizePythonInterpreter`` and ``__dso_handle`` in the symbol table
    (``.symtab``, which holds local symbols such as ``__dso_handle``) of a 64-bit
    little-endian ELF file; empty if the file is not one or is stripped."""
    data = path.read_bytes()
    if data[:4] != b"\x7fELF" or data[4] != 2 or data[5] != 1:   # ELFCLASS64, ELFDATA2LSB
        return {}
    (shoff,) = struct.unpack_from("<Q", data, 0x28)
    shentsize, shnum = struct.unpack_from("<HH", data, 0x3A)
    # Elf64_Shdr: name, type, flags, addr, offset, size, link, info, addralign, entsize
    sections = [struct.unpack_from("<IIQQQQIIQQ", data, shoff + i * shentsize) for i in range(shnum)]
    wanted = {FINALIZE.encode(), DSO_HANDLE.encode()}
    found: dict[str, int] = {}
    for _, sh_type, _, _, offset, size, link, _, _, _ in sections:
        if sh_type != 2:   # SHT_SYMTAB
            continue
        strtab = sections[link][4]
        for at in range(offset, offset + size, 24):   # Elf64_Sym: name, info, other, shndx, value, size
            name_at, _, _, shndx, value, _ = struct.unpack_from("<IBBHQQ", data, at)
            name = data[strtab + name_at:data.index(b"\0", strtab + name_at)]
            if name in wanted and shndx != 0:   # defined here, not an undefined reference
                found[name.decode()] = value
    return found


def _offsets(path: Path) -> tuple[int, int] | None:
    st = path.stat()
    key = (st.st_dev, st.st_ino, st.st_mtime_ns)
    if key not in _SYMBOLS:
        found = elf_symbols(path)
        _SYMBOLS[key] = (found[FINALIZE], found[DSO_HANDLE]) if FINALIZE in found and DSO_HANDLE in found else None
    return _SYMBOLS[key]


def _pending(sem: int) -> bool:
    value = ctypes.c_int(-1)
    return _c().sem_getvalue(sem, ctypes.byref(value)) == 0 and value.value == 0


def guard_library(path: Path) -> bool:
    """Register the exit guard of the library file ``path`` if this process has it loaded and
    it is pythonfmu's (module doc). True if the loaded copy is guarded (now or before)."""
    c = _c()
    handle = c.dlopen(os.fsencode(path), os.RTLD_LAZY | os.RTLD_NOLOAD)   # the loaded copy, or NULL
    if not handle:
        return False
    try:
        fn = c.dlsym(handle, FINALIZE.encode())
        offsets = _offsets(path) if fn else None
        if offsets is None:
            return False
        base = fn - offsets[0]
        dso = base + offsets[1]
        info = _DlInfo()
        # the symbol table is the loaded image's: __dso_handle lies in this library and, as
        # GCC's crtstuff defines it in a shared object, holds its own address
        if not (c.dladdr(dso, ctypes.byref(info)) and info.dli_fbase == base
                and ctypes.c_void_p.from_address(dso).value == dso):
            return False
        if dso in _GUARDS and _pending(_GUARDS[dso]):
            return True
        sem = c.calloc(1, _SEM_T_BYTES)
        if not sem or c.sem_init(sem, 0, 0) != 0:
            return False
        # handlers run last-registered first: finalizePythonInterpreter, then the post that marks the pair as run
        if c.__cxa_atexit(ctypes.cast(c.sem_post, ctypes.c_void_p).value, sem, dso) != 0:
            return False
        if c.__cxa_atexit(fn, None, dso) != 0:
            return False   # a later instance tries again (the lone post is harmless)
        _GUARDS[dso] = sem
        return True
    finally:
        c.dlclose(handle)   # the host's own reference keeps the library loaded


def guard(resources: str | os.PathLike | None) -> bool:
    """Guard the FMU library of the slave whose resources folder is ``resources``
    (``<unzipped FMU>/resources``; the library is ``<unzipped FMU>/binaries/linux64/*.so``).
    A no-op returning False off Linux, at build time and when the slave runs without its FMU
    (the library is not loaded then). Never raises: a slave must not (``marinefmu.fmu.slave``)."""
    if not sys.platform.startswith("linux") or not resources:
        return False
    try:
        libraries = sorted((Path(resources).parent / "binaries" / "linux64").glob("*.so"))
        return any([guard_library(lib) for lib in libraries])
    except Exception:  # noqa: BLE001 - the guard is a safety net; the slave works without it
        return False


def guarded() -> int:
    """Number of loaded library copies whose exit guard has not run yet."""
    return sum(_pending(sem) for sem in _GUARDS.values())
