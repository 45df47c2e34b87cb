"""The output folder's lock (optdesign/storage/folder_lock.py): who holds it, as read from the lock file."""

from __future__ import annotations

import pytest

from optdesign.storage import _lock_holder


# --- store: the lock's holder, a store with another hard link ---------------------------
@pytest.mark.parametrize(
    ("content", "holder"),
    [
        (b"12345\n", "pid 12345"),
        (b"not a pid", "pid unknown"),
        (b"\xff\xfe", "pid unknown"),  # not UTF-8
        (b"1" * 65, "pid unknown"),  # more than a pid: not read
        (b"1" * 64, "pid " + "1" * 64),
    ],
)
def test_lock_holder_reads_only_a_pid(tmp_path, content, holder):
    lock = tmp_path / "lock"
    lock.write_bytes(content)
    assert _lock_holder(lock) == holder


def test_lock_holder_of_a_missing_lock_is_unknown(tmp_path):
    assert _lock_holder(tmp_path / "lock") == "pid unknown"
