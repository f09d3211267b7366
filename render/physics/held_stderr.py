"""fd 2 held while a block runs: what Taichi's C++ side and LLVM write there (past Python's sys.stderr) goes to a
temporary file, and afterwards only what the caller lets through reaches the real fd 2."""
import contextlib
import os
import sys
import tempfile
import threading
from typing import Callable

# fd 2 is the process's: a second thread's hold would save the first one's file as "the real fd 2" and put it
# back after the first had restored it. Holds take turns (re-entrant: nested holds in one thread unwind in order).
_TURN = threading.RLock()


@contextlib.contextmanager
def held(let_through: Callable[[bytes, bool], bytes]):
    """Run the block with fd 2 in a temporary file; then write let_through(text, ok) to fd 2, ok being whether
    the block finished without raising."""
    with _TURN:
        try:
            sys.stderr.flush()
            saved = os.dup(2)
        except (OSError, ValueError):  # no fd 2 to hold
            yield
            return
        with tempfile.TemporaryFile() as file:
            os.dup2(file.fileno(), 2)
            ok = False
            try:
                yield
                ok = True
            finally:
                os.dup2(saved, 2)
                os.close(saved)
                file.seek(0)
                text = let_through(file.read(), ok)
                if text:
                    os.write(2, text)
