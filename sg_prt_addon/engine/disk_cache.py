"""Derived data a render would rebuild in every new process, kept on disk: the environment's prefiltered layers
and SG fit (about 1 s for a 1024 x 512 HDRI), the engine's tables of the code alone (the clamped cosine, GGX
albedo, layering: about 1 s together) and the SH technique's tables (techniques reach it through
DrawContext.cached_arrays: a parametric model's, about 1 s; a lobe fit's, about 5 s for 64 x 64 texels).  A
batch job (`blender -b -f 1`) is one process a frame, and without this each paid them on its first render.

Entries are .npz files (numpy arrays only, no pickle, and the list of their names) named by a digest of
what they were made from: the caller's key (an image's pixels, a table's name) and this add-on's Python
source, so any change to the code or to the image is a miss, never a stale hit.  A file that fails to read
(truncated, corrupt, an array missing) is rebuilt and replaced; a folder that cannot be made leaves the cache
off with one warning.  Writes go through a temporary file and a rename, so a process killed mid-write leaves
no half entry.  The folder is bounded (MAX_BYTES): the least recently used entries go first.

Where: ``SG_PRT_CACHE_DIR`` if set (empty: no disk cache), else the extension's user folder
(``bpy.utils.extension_path_user``, which Blender keeps across upgrades), else the platform's user cache
(``$XDG_CACHE_HOME/sg-prt``) when running from the pip module.
"""
import hashlib
import os
import sys
import tempfile
import zipfile
from functools import lru_cache
from pathlib import Path

import numpy as np

DIRECTORY_VARIABLE = "SG_PRT_CACHE_DIR"
MAX_BYTES = 512 * 2 ** 20
SUFFIX = ".npz"
MANIFEST = "_names"           # the member listing the entry's arrays
_PACKAGE_ROOT = Path(__file__).resolve().parents[1]
_warned = set()


def directory():
    """The cache folder (created), or None when the disk cache is off or no folder can be made."""
    configured = os.environ.get(DIRECTORY_VARIABLE)
    if configured is not None:
        path = Path(configured) if configured else None
    else:
        path = _default_directory()
    if path is None:
        return None
    try:
        path.mkdir(parents=True, exist_ok=True)
    except OSError as error:
        _warn_once(f"SG-PRT: no disk cache ({error}); environments and tables are rebuilt in each process")
        return None
    return path


def _default_directory():
    package = __name__.rsplit(".engine.", 1)[0]
    if package.startswith("bl_ext."):
        try:
            import bpy
            return Path(bpy.utils.extension_path_user(package, path="cache"))
        except (ImportError, AttributeError, ValueError):
            pass
    base = os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache"
    return Path(base) / "sg-prt"


@lru_cache(maxsize=1)
def code_digest():
    """Digest of this add-on's Python sources and numpy's version: what every entry was made by."""
    digest = hashlib.blake2b(digest_size=16)
    digest.update(np.__version__.encode())
    for path in sorted(_PACKAGE_ROOT.rglob("*")):
        if path.suffix == ".py" and path.is_file():
            digest.update(str(path.relative_to(_PACKAGE_ROOT)).encode())
            digest.update(path.read_bytes())
    return digest.hexdigest()


def entry_name(kind, key):
    """File name of an entry: ``kind`` (a word) and a digest of ``key`` (bytes or str parts) and the code."""
    digest = hashlib.blake2b(digest_size=20)
    digest.update(code_digest().encode())
    for part in key:
        digest.update(part if isinstance(part, bytes) else repr(part).encode())
        digest.update(b"\0")
    return f"{kind}-{digest.hexdigest()}{SUFFIX}"


def load_or_build(kind, key, build, folder=None):
    """The arrays ``build()`` returns (a dict of name -> ndarray), read from the cache when an entry for
    ``kind`` and ``key`` exists and reads whole, else built and stored.  ``folder``: the cache folder
    (default: ``directory()``)."""
    folder = directory() if folder is None else Path(folder)
    if folder is None:
        return build()
    path = folder / entry_name(kind, key)
    arrays = _read(path)
    if arrays is not None:
        return arrays
    arrays = {name: np.asarray(value) for name, value in build().items()}
    _write(path, arrays)
    return arrays


def _read(path):
    try:
        with np.load(path, allow_pickle=False) as entry:
            # reading each member checks its CRC; the manifest, that none is missing
            arrays = {str(name): entry[str(name)] for name in entry[MANIFEST]}
    except FileNotFoundError:
        return None
    except (OSError, ValueError, EOFError, KeyError, zipfile.BadZipFile) as error:
        print(f"SG-PRT: cache entry {path.name} is unreadable ({error}); rebuilding it", file=sys.stderr)
        return None
    try:
        os.utime(path)                      # recently used: pruned last
    except OSError:
        pass
    return arrays


def _write(path, arrays):
    temporary = None
    try:
        descriptor, temporary = tempfile.mkstemp(prefix=".writing-", suffix=".tmp", dir=path.parent)
        with os.fdopen(descriptor, "wb") as stream:
            np.savez(stream, **arrays, **{MANIFEST: np.array(sorted(arrays))})
        os.replace(temporary, path)
    except OSError as error:
        _warn_once(f"SG-PRT: could not write the disk cache in {path.parent} ({error})")
        if temporary is not None and os.path.exists(temporary):
            os.unlink(temporary)
        return
    prune(path.parent)


def prune(folder, max_bytes=MAX_BYTES):
    """Delete the least recently used entries until the folder's entries take at most ``max_bytes``."""
    entries = []
    for path in Path(folder).glob("*" + SUFFIX):
        try:
            status = path.stat()
        except OSError:
            continue
        entries.append((status.st_mtime, status.st_size, path))
    total = sum(size for _, size, _ in entries)
    for _, size, path in sorted(entries):
        if total <= max_bytes:
            break
        try:
            path.unlink()
            total -= size
        except OSError:
            pass


def _warn_once(message):
    if message not in _warned:
        _warned.add(message)
        print(message, file=sys.stderr)
