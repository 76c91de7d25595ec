"""Writing files whole or not at all: the one atomic writer of partsim's Python modules."""

import os

__all__ = ["atomic_write"]


def atomic_write(path, write, sync: bool = True) -> None:
    """Calls ``write(file)`` on a binary temporary file beside ``path`` (named after this
    process, so that two processes never share one), then renames it onto ``path``: readers,
    and a process killed half-way, see the old file or the new one, never a part. ``sync``
    flushes the file to disk before the rename, so that a crash of the machine cannot leave an
    empty file under the final name either."""
    path = os.fspath(path)
    tmp = f"{path}.tmp{os.getpid()}"
    try:
        with open(tmp, "wb") as f:
            write(f)
            if sync:
                f.flush()
                os.fsync(f.fileno())
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.remove(tmp)
        raise
