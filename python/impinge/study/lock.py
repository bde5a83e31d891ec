"""A study folder's lock: the runner that writes into OUT holds OUT/.lock (a whole run) or OUT/.lock-I-of-N (shard
I of N), so that a second runner whose tasks overlap (a whole run and anything, or one shard twice) refuses instead
of deleting the first one's half-written task folders; shards of one study share the folder (their tasks are
disjoint).

The rule and wording are the CLI's for its output folder (libcore/src/session/outputs.cpp, `.impinge.lock`): the
file holds `pid host command start`; a holder that runs on this host, or any on another host (whether it still
runs cannot be told from here), is refused naming it; a lock whose process is gone (same host) or that holds no
pid (empty: the disk was full when it was written) is taken over."""
import os
import socket
import time

from .spec import StudyError

COMMAND = "impinge.study run"


def _alive(pid):
    """Whether process `pid` of this machine still runs (EPERM: it runs as another user)."""
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    except (OverflowError, ValueError):
        return False
    return True


def holder(path):
    """The holder a lock file names -> (pid, host, command, start); pid 0 when it names none (empty, cut short).
    Also reads the lock of earlier study runners ('host pid')."""
    try:
        with open(path) as f:
            parts = f.read().split()
    except OSError:
        parts = []
    if len(parts) == 2 and parts[1].isdigit() and not parts[0].isdigit():  # an earlier runner's 'host pid'
        return int(parts[1]), parts[0], COMMAND, ""
    if len(parts) < 3 or not parts[0].isdigit():
        return 0, parts[1] if len(parts) > 1 else "", "", ""
    return int(parts[0]), parts[1], " ".join(parts[2:-1]) or COMMAND, parts[-1]


def refuse_or_clear(out, path):
    """Refuse (StudyError naming the holder) when the lock at `path` is held by a live runner of this host or by
    a runner of another host; remove it when its runner is gone, it names none, or it is this process's own."""
    if not os.path.lexists(path):
        return
    pid, host, command, start = holder(path)
    try:
        fresh = pid == 0 and time.time() - os.stat(path).st_mtime < 1.0
    except OSError:
        fresh = False
    if fresh:  # created this instant by a runner that has yet to write its line: read it again
        time.sleep(0.2)
        pid, host, command, start = holder(path)
    here = socket.gethostname()
    ours = pid == os.getpid() and host == here
    since = f", since {start}" if start else ""
    if pid > 0 and host == here and not ours and _alive(pid):
        raise StudyError(f"{out}: in use by {command} (pid {pid}{since}): wait for it to end, or give another --out")
    if pid > 0 and host and host != here:
        raise StudyError(f"{out}: in use by {command} on {host} (pid {pid}{since}); if that run has ended, remove "
                         f"{path}")
    try:  # left by a runner that ended (or empty: a full disk): taken over
        os.unlink(path)
    except FileNotFoundError:
        pass
    except OSError as e:
        raise StudyError(f"{path}: cannot remove the study folder's stale lock ({e.strerror})") from None


class OutLock:
    """OUT/.lock or OUT/.lock-I-of-N held while a runner writes into OUT (a context manager). A whole run refuses
    while any lock of OUT is held; a shard while the whole run's or its own is."""

    def __init__(self, out, shard=None):
        self.out = out
        self.path = os.path.join(out, ".lock" if not shard else f".lock-{shard[0]}-of-{shard[1]}")
        self.command = COMMAND + (f" --shard {shard[0]}/{shard[1]}" if shard else "")
        self.shard = shard

    def _others(self):
        if self.shard:
            return [os.path.join(self.out, ".lock")]
        try:
            names = os.listdir(self.out)
        except OSError as e:
            raise StudyError(f"{self.out}: cannot read the study folder ({e.strerror})") from None
        return [os.path.join(self.out, n) for n in sorted(names) if n.startswith(".lock-")]

    def __enter__(self):
        for other in self._others():
            refuse_or_clear(self.out, other)
        start = time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime())
        mine = f"{os.getpid()} {socket.gethostname()} {self.command} {start}\n".encode()
        for _ in range(3):
            try:
                fd = os.open(self.path, os.O_WRONLY | os.O_CREAT | os.O_EXCL | os.O_CLOEXEC, 0o644)
            except FileExistsError:
                refuse_or_clear(self.out, self.path)
                continue
            except OSError as e:
                raise StudyError(f"{self.path}: cannot create the study folder's lock ({e.strerror})") from None
            try:
                written = os.write(fd, mine) == len(mine)
            except OSError:
                written = False
            try:
                os.close(fd)
            except OSError:
                written = False
            if not written:
                self._remove()
                raise StudyError(f"{self.path}: cannot write the study folder's lock (is the disk full?)")
            return self
        raise StudyError(f"{self.path}: another runner takes the folder at the same moment; try again")

    def _remove(self):
        try:
            os.unlink(self.path)
        except OSError:
            pass

    def __exit__(self, *exc):
        pid, host, _, _ = holder(self.path)
        if pid == os.getpid() and host == socket.gethostname():  # only our own
            self._remove()
        return False
