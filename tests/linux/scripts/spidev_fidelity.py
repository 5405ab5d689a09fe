"""What the kernel does with a spidev node that the emulated one must do too: EBADF for a read
on an O_WRONLY file and a write on an O_RDONLY one (the access mode in F_GETFL), ENOTDIR for a
path that goes on past the node, every spelling of the node's path (//dev, /dev/./, /dev/../dev,
relative to /dev, relative to a directory descriptor) opening the same node, and EINVAL for a
transfer slower than the controller can clock. Prints key=value lines (errno names, or "ok")."""
import errno
import fcntl
import os
import stat

import spidev

NODE = "/dev/spidev0.0"


def outcome(f):
    try:
        r = f()
        return "ok" if r is None or isinstance(r, (int, bytes, list)) else str(r)
    except OSError as e:
        return errno.errorcode.get(e.errno, str(e.errno))


def show(key, f):
    print(f"{key}={outcome(f)}", flush=True)


wr = os.open(NODE, os.O_WRONLY)
show("read_on_wronly", lambda: os.read(wr, 1))
show("write_on_wronly", lambda: os.write(wr, b"\x00"))
print(f"wronly_accmode={fcntl.fcntl(wr, fcntl.F_GETFL) & os.O_ACCMODE == os.O_WRONLY}")
dup = os.dup(wr)
show("read_on_dup_of_wronly", lambda: os.read(dup, 1))
os.close(dup)
os.close(wr)
rd = os.open(NODE, os.O_RDONLY)
show("write_on_rdonly", lambda: os.write(rd, b"\x00"))
show("read_on_rdonly", lambda: os.read(rd, 1))
print(f"rdonly_accmode={fcntl.fcntl(rd, fcntl.F_GETFL) & os.O_ACCMODE == os.O_RDONLY}")
os.close(rd)

for key, path in [("trailing_slash", NODE + "/"), ("trailing_dot", NODE + "/."), ("below", NODE + "/x"),
                  ("dotdot_after", NODE + "/..")]:
    show(f"open_{key}", lambda: os.close(os.open(path, os.O_RDWR)))
    show(f"stat_{key}", lambda: os.stat(path))

for key, path in [("double_slash", "//dev/spidev0.0"), ("dot", "/dev/./spidev0.0"), ("dotdot", "/dev/../dev/spidev0.0"),
                  ("mixed", "/./dev//./spidev0.0")]:
    def opened(path=path):
        fd = os.open(path, os.O_RDWR)
        st = os.fstat(fd)
        os.close(fd)
        return "ok" if stat.S_ISCHR(st.st_mode) and os.major(st.st_rdev) == 153 else "not the node"
    show(f"open_{key}", opened)
    show(f"stat_{key}", lambda path=path: "ok" if stat.S_ISCHR(os.stat(path).st_mode) else "not a char device")

os.chdir("/dev")
show("open_relative", lambda: os.close(os.open("spidev0.0", os.O_RDWR)))
show("open_relative_dot", lambda: os.close(os.open("./spidev0.0", os.O_RDWR)))
d = os.open("/", os.O_RDONLY | os.O_DIRECTORY)
show("open_dir_fd", lambda: os.close(os.open("dev/spidev0.0", os.O_RDWR, dir_fd=d)))
os.close(d)

s = spidev.SpiDev()
s.open(0, 0)
s.mode = 3
show("set_speed_1hz", lambda: setattr(s, "max_speed_hz", 1))  # spidev keeps it; the transfer is refused
show("xfer_at_1hz", lambda: s.xfer2([0, 0, 0, 0]))
show("read_at_1hz", lambda: s.readbytes(1))
s.max_speed_hz = 5000000
show("xfer_at_3814hz", lambda: s.xfer2([0], 3814))
show("xfer_at_3815hz", lambda: s.xfer2([0], 3815))
show("xfer_at_5mhz", lambda: s.xfer2([0]))
