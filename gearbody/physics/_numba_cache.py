"""Keep numba's on-disk cache consistent across the physics modules.

numba invalidates a cached function only when its *own* source file changes. A compiled kernel that
calls into another module (lateral.py -> mesh.py) keeps the old callee after that module changes:
wrong forces, silently. So the cache files of this package are dropped whenever any physics source
differs from the set they were compiled with (a hash of all sources, stored next to them).
"""

from __future__ import annotations

import hashlib
from pathlib import Path


def refresh(package_dir: Path) -> bool:
    """Delete stale numba cache files of ``package_dir``; True if something was deleted."""
    sources = sorted(package_dir.glob("*.py"))
    digest = hashlib.sha256(b"".join(p.read_bytes() for p in sources)).hexdigest()
    cache = package_dir / "__pycache__"
    tag = cache / "numba-sources.sha256"
    try:
        if tag.read_text() == digest:
            return False
    except OSError:
        pass
    removed = False
    try:
        cache.mkdir(exist_ok=True)
        for f in list(cache.glob("*.nbi")) + list(cache.glob("*.nbc")):
            f.unlink(missing_ok=True)
            removed = True
        tag.write_text(digest)
    except OSError:  # read-only install: numba falls back to its own cache locator
        pass
    return removed


refresh(Path(__file__).resolve().parent)
