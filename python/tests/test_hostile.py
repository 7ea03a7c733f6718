"""Hostile inputs (issue 32 §2): read_image refuses what is not a regular file (a device, a link to one,
a FIFO, a folder) with one line, before any codec sees it, and never reads without end."""
import os
import signal

import pytest

import iblkit


@pytest.fixture
def deadline():
    """Fails the test instead of hanging when a read never ends."""
    def expired(signum, frame):
        raise TimeoutError("read_image did not return within 20 s")
    old = signal.signal(signal.SIGALRM, expired)
    signal.alarm(20)
    yield
    signal.alarm(0)
    signal.signal(signal.SIGALRM, old)


@pytest.mark.parametrize("kind", ["zero", "urandom", "link", "fifo", "folder"])
def test_read_image_refuses_what_is_not_a_regular_file(tmp_path, deadline, kind):
    path = {"zero": "/dev/zero", "urandom": "/dev/urandom"}.get(kind, str(tmp_path / "probe.exr"))
    if kind == "link":
        os.symlink("/dev/zero", path)
    elif kind == "fifo":
        os.mkfifo(path)
    elif kind == "folder":
        os.mkdir(path)
    with pytest.raises(Exception) as e:
        iblkit.read_image(path)
    msg = str(e.value)
    assert "\n" not in msg and path in msg
    assert ("not a regular file" in msg) or (kind == "folder" and "is a folder" in msg), msg
