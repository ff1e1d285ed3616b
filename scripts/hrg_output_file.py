"""Files written whole or not at all, for the Python tools (hrg_report.py, hrg_batch.py).

The same rules as the C++ AtomicOutputFile (include/hrg_gyro/core/common/atomic_file.h), so that a
page written by `hrg_bag report` is as safe as a bag written by `hrg_bag process`:

- the content goes to a temporary beside the target, named <target>.tmp.<pid>.XXXXXX as the C++
  names its own, so that either writer recognises and removes what a killed other one left behind;
  it is synced, renamed over the target, and the directory is synced;
- on any failure (a full disk, an exception, KeyboardInterrupt) the temporary is removed and an
  existing target is untouched;
- a symbolic link at the target is followed (the file it points to is replaced, the link stays);
  a replaced file keeps its mode (owner and group where allowed); a new one gets 0644 narrowed by
  the umask; a target that exists and is not a regular file (FIFO, device, directory) is refused;
- check_output_paths refuses, before anything is read, an output that is one of the inputs or
  another output (device and inode after following links, or the link-resolved absolute path of
  a file that does not exist yet), or an existing output that is not a regular file.

Two kinds of error: PathRefused (bad usage: the tools exit 2) and OutputWriteError (the file could
not be written: exit 3).
"""
import os
import secrets
import stat
import string
import time

MAX_LINK_HOPS = 40
# As the C++: a temporary whose writer is gone is stale once older than the current write; one
# whose writer's pid is still in use (perhaps reused) only after a day. Legacy names (no pid) after
# an hour.
STALE_AFTER_SECONDS = 24 * 3600
LEGACY_STALE_AFTER_SECONDS = 3600
NEW_FILE_MODE = 0o644
_ALNUM = frozenset(string.ascii_letters + string.digits)
_RANDOM_CHARS = string.ascii_letters + string.digits


class PathRefused(Exception):
    """An output that must not be written, or an input that must not be read: exit 2."""


class OutputWriteError(Exception):
    """The output could not be written (the target is as it was): exit 3."""


def shown(value, limit=80):
    """repr(value) for a message, cut to `limit` characters: a 10 MB field must not flood stderr."""
    text = repr(value)
    if len(text) <= limit:
        return text
    return "%s... (%d characters)" % (text[:limit], len(text))


def directory_of(path):
    """The directory part of a path ("." for a bare name), as the C++ directoryOf."""
    slash = path.rfind("/")
    return "." if slash < 0 else ("/" if slash == 0 else path[:slash])


def _base_name_of(path):
    return path[path.rfind("/") + 1:]


def kind_of(mode):
    if stat.S_ISDIR(mode):
        return "a directory"
    if stat.S_ISFIFO(mode):
        return "a FIFO (named pipe)"
    if stat.S_ISCHR(mode):
        return "a character device"
    if stat.S_ISBLK(mode):
        return "a block device"
    if stat.S_ISSOCK(mode):
        return "a socket"
    if stat.S_ISLNK(mode):
        return "a symbolic link"
    return "not a regular file"


def _reason(error):
    return error.strerror or str(error)


def resolve_output_target(path):
    """`path` with symbolic links in its last component followed; a missing path is returned as is."""
    current = path
    for hops in range(MAX_LINK_HOPS + 1):
        try:
            st = os.lstat(current)
        except FileNotFoundError:
            return current  # a new file: its directory is checked when the temporary is created
        except OSError as e:
            raise OutputWriteError("cannot inspect '%s': %s" % (current, _reason(e)))
        if not stat.S_ISLNK(st.st_mode):
            return current
        if hops == MAX_LINK_HOPS:
            break
        try:
            link = os.readlink(current)
        except OSError as e:
            raise OutputWriteError("cannot read symbolic link '%s': %s" % (current, _reason(e)))
        current = link if link.startswith("/") else directory_of(current) + "/" + link
    raise OutputWriteError("too many levels of symbolic links from '%s'" % path)


# ---------------------------------------------------------------------------------------------
# Temporaries: the C++ temporaryOwner, character for character, so that both agree.

def _all_digits(s):
    return bool(s) and all(c in "0123456789" for c in s)


def _is_mkstemp_suffix(s):
    return len(s) == 6 and all(c in _ALNUM for c in s)


def _is_temporary_suffix(s):
    return not s or (len(s) <= 16 and s[0] == "." and all(c in _ALNUM or c == "." for c in s))


def temporary_owner(name, base):
    """The writer's pid in a temporary's name (<base>.tmp.<pid>.XXXXXX[suffix], <base>.bak.tmp.<pid>.XXXXXX),
    0 for a legacy name (<base>.tmp.XXXXXX, <base>.bak.tmp), -1 for a name that is not one (never touched)."""
    if name == base + ".bak.tmp":
        return 0
    for prefix in (base + ".tmp.", base + ".bak.tmp."):
        if not name.startswith(prefix):
            continue
        rest = name[len(prefix):]
        dot = rest.find(".")
        if dot < 0:
            return 0 if _is_mkstemp_suffix(rest) and prefix == base + ".tmp." else -1
        pid, suffix = rest[:dot], rest[dot + 1:]
        if len(pid) > 9 or not _all_digits(pid) or not _is_mkstemp_suffix(suffix[:6]) or \
                not _is_temporary_suffix(suffix[6:]):
            return -1
        owner = int(pid)
        return owner if owner > 0 else -1
    return -1


def _process_is_gone(pid):
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return True
    except OSError:
        return False  # it exists (another user's)
    return False


def remove_stale_temporaries(target, write_start_ns=None):
    """Removes temporaries of `target` left by killed writers: ours by name only, regular files only,
    older than this write, and whose writer is gone (or a day old)."""
    if write_start_ns is None:
        write_start_ns = time.time_ns()
    directory, base = directory_of(target), _base_name_of(target)
    try:
        names = os.listdir(directory)
    except OSError:
        return  # creating the temporary reports the problem
    me = os.getpid()
    for name in names:
        owner = temporary_owner(name, base)
        if owner < 0 or owner == me:
            continue  # not ours, or a concurrent write of this process
        path = directory + "/" + name
        try:
            st = os.lstat(path)
        except OSError:
            continue
        if not stat.S_ISREG(st.st_mode) or st.st_mtime_ns >= write_start_ns:
            continue
        age = write_start_ns // 10**9 - st.st_mtime_ns // 10**9
        stale = age > LEGACY_STALE_AFTER_SECONDS if owner == 0 else (_process_is_gone(owner) or
                                                                    age > STALE_AFTER_SECONDS)
        if stale:
            try:
                os.unlink(path)
            except OSError:
                pass


def process_umask():
    """The umask, read without changing it (os.umask would race with threads creating files)."""
    try:
        with open("/proc/self/status") as f:
            for line in f:
                if line.startswith("Umask:"):
                    return int(line.split()[1], 8) & 0o777
    except (OSError, ValueError, IndexError):
        pass
    return 0o022


def _create_temporary(target):
    """A new 0600 file <target>.tmp.<pid>.XXXXXX (six letters or digits, as mkstemp makes them)."""
    for _ in range(100):
        name = "%s.tmp.%d.%s" % (target, os.getpid(), "".join(secrets.choice(_RANDOM_CHARS) for _ in range(6)))
        try:
            return os.open(name, os.O_WRONLY | os.O_CREAT | os.O_EXCL | os.O_CLOEXEC, 0o600), name
        except FileExistsError:
            continue
        except OSError as e:
            raise OutputWriteError("cannot create a temporary file beside '%s': %s" % (target, _reason(e)))
    raise OutputWriteError("cannot create a temporary file beside '%s': every name tried exists" % target)


class AtomicOutputFile:
    """with AtomicOutputFile(path) as f: f.write(text); f.commit()  -- leaving the block without
    commit() (an exception, KeyboardInterrupt) removes the temporary and leaves the target as it was."""

    def __init__(self, path):
        if not path:
            raise OutputWriteError("empty output file name")
        self.requested_path = path
        self.target_path = resolve_output_target(path)
        self._existing = None
        try:
            st = os.stat(self.target_path)
        except FileNotFoundError:
            pass
        except OSError as e:
            raise OutputWriteError("cannot inspect '%s': %s" % (self.target_path, _reason(e)))
        else:
            if not stat.S_ISREG(st.st_mode):
                raise OutputWriteError("refusing to replace '%s': it is %s, not a regular file" %
                                       (self.target_path, kind_of(st.st_mode)))
            self._existing = st
        remove_stale_temporaries(self.target_path)
        self._fd, self.temporary_path = -1, None
        self._finished = False
        self._fd, self.temporary_path = _create_temporary(self.target_path)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.discard()
        return False

    def _unchanged(self):
        return " (the existing file is unchanged)" if self._existing is not None else ""

    def _fail(self, what, error):
        self.discard()
        raise OutputWriteError("%s%s: %s" % (what, self._unchanged(), _reason(error)))

    def write(self, data):
        if self._finished:
            raise ValueError("AtomicOutputFile for '%s' is already committed or discarded" % self.target_path)
        if isinstance(data, str):
            try:  # file names that are not UTF-8 come back as they were
                data = data.encode("utf-8", "surrogateescape")
            except UnicodeEncodeError:
                data = data.encode("utf-8", "replace")
        view = memoryview(data)
        try:
            while view:
                view = view[os.write(self._fd, view):]
        except OSError as e:
            self._fail("cannot write '%s'" % self.target_path, e)
        except BaseException:
            self.discard()
            raise

    def commit(self):
        """Mode (and owner), fsync, rename over the target, fsync of the directory."""
        if self._finished:
            raise ValueError("AtomicOutputFile for '%s' is already committed or discarded" % self.target_path)
        try:
            try:
                if self._existing is not None:
                    try:
                        os.fchown(self._fd, self._existing.st_uid, self._existing.st_gid)
                    except PermissionError:
                        try:
                            os.fchown(self._fd, -1, self._existing.st_gid)
                        except OSError:
                            pass
                    except OSError:
                        pass
                    # After fchown, which clears set-user-id bits that the mode then restores.
                    os.fchmod(self._fd, stat.S_IMODE(self._existing.st_mode))
                else:
                    os.fchmod(self._fd, NEW_FILE_MODE & ~process_umask())
            except OSError as e:
                self._fail("cannot set the mode of '%s'" % self.temporary_path, e)
            try:
                os.fsync(self._fd)
            except OSError as e:
                self._fail("cannot sync '%s'" % self.temporary_path, e)
            try:
                os.rename(self.temporary_path, self.target_path)
            except OSError as e:
                self._fail("cannot rename '%s' over '%s'" % (self.temporary_path, self.target_path), e)
        except BaseException:
            self.discard()
            raise
        self._finished = True
        try:
            os.close(self._fd)
        except OSError:
            pass  # synced and renamed already
        self._fd = -1
        _sync_directory(directory_of(self.target_path))

    def discard(self):
        """Drops the temporary; the target is untouched. Safe to call more than once."""
        if self._finished:
            return
        self._finished = True
        if self._fd >= 0:
            try:
                os.close(self._fd)
            except OSError:
                pass
            self._fd = -1
        if self.temporary_path:
            try:
                os.unlink(self.temporary_path)
            except OSError:
                pass


def _sync_directory(directory):
    try:
        fd = os.open(directory, os.O_RDONLY | os.O_DIRECTORY | os.O_CLOEXEC)
    except OSError:
        return  # best effort: the rename has happened
    try:
        os.fsync(fd)
    except OSError:
        pass
    finally:
        os.close(fd)


def write_file_atomically(path, data):
    with AtomicOutputFile(path) as f:
        f.write(data)
        f.commit()


# ---------------------------------------------------------------------------------------------
# Inputs and outputs kept apart, as the C++ checkDistinct and hrg_bag's checkOutputPaths.

def _identify(path):
    try:
        st = os.stat(path)
        return ("inode", st.st_dev, st.st_ino)
    except NotADirectoryError:
        return ("path", os.path.abspath(path))  # under a file: nothing can exist there, input or output
    except OSError:
        pass
    try:
        target = resolve_output_target(path)
    except OutputWriteError as e:
        raise PathRefused(str(e))
    return ("path", os.path.join(os.path.realpath(directory_of(target)), _base_name_of(target)))


def check_distinct(inputs, outputs):
    """PathRefused, naming both, for an output that is an input or another output."""
    input_ids = [_identify(p) for p in inputs]
    output_ids = [_identify(p) for p in outputs]
    for o, out in enumerate(outputs):
        for i, inp in enumerate(inputs):
            if output_ids[o] == input_ids[i]:
                raise PathRefused("output '%s' is the same file as input '%s': writing it would destroy what is "
                                  "being read" % (out, inp))
        for other in range(o):
            if output_ids[o] == output_ids[other]:
                raise PathRefused("outputs '%s' and '%s' are the same file" % (outputs[other], out))


def check_output_paths(inputs, outputs):
    """check_distinct, after refusing an existing output that is not a regular file (never opened)."""
    inputs, outputs = [p for p in inputs if p], [p for p in outputs if p]
    for p in outputs:
        try:
            st = os.stat(p)
        except OSError:
            continue  # a new file (a link loop is refused by check_distinct)
        if not stat.S_ISREG(st.st_mode):
            raise PathRefused("output '%s' is %s, not a regular file: refusing to replace it" %
                              (p, kind_of(st.st_mode)))
    check_distinct(inputs, outputs)


def read_regular_file(path, what, max_bytes):
    """The bytes of a regular file of at most `max_bytes`, as the C++ readBoundedRegularFile: a FIFO,
    a device or a directory is refused without being opened in a way that could block."""
    try:
        st = os.stat(path)
    except OSError as e:
        raise PathRefused("cannot read %s '%s': %s" % (what, path, _reason(e)))

    def refuse_kind(mode):
        if not stat.S_ISREG(mode):
            raise PathRefused("%s '%s' is %s, not a regular file" % (what, path, kind_of(mode)))

    refuse_kind(st.st_mode)
    if st.st_size > max_bytes:
        raise PathRefused("%s '%s' is %d bytes, above the limit of %d" % (what, path, st.st_size, max_bytes))
    try:
        # O_NONBLOCK: should the path have become a FIFO since the stat, open must not hang.
        fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK | os.O_NOCTTY | os.O_CLOEXEC)
    except OSError as e:
        raise PathRefused("cannot read %s '%s': %s" % (what, path, _reason(e)))
    try:
        refuse_kind(os.fstat(fd).st_mode)
        chunks, size = [], 0
        while size <= max_bytes:
            chunk = os.read(fd, min(1 << 20, max_bytes + 1 - size))
            if not chunk:
                break
            chunks.append(chunk)
            size += len(chunk)
    except OSError as e:
        raise PathRefused("error while reading %s '%s': %s" % (what, path, _reason(e)))
    finally:
        os.close(fd)
    if size > max_bytes:
        raise PathRefused("%s '%s' grew past the limit of %d bytes while being read" % (what, path, max_bytes))
    return b"".join(chunks)
