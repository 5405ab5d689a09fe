#!/bin/busybox sh
# /init of the test VM (tests/vm/build-vm.sh packs it): loads the modules, mounts the host's
# root read-only over 9p (tag hostroot) with tmpfs on /tmp, /run and /dev/shm (the host
# directories listed in the share's "keep" file stay visible at their paths), the writable share
# "work" at /tmp/vmwork, and runs /tmp/vmwork/command in that root as root. Its output
# goes to the console; its exit code to /tmp/vmwork/exit-code. Then the VM powers off.
/bin/busybox --install -s /bin
export PATH=/bin
mount -t proc proc /proc
mount -t sysfs sysfs /sys
mount -t devtmpfs devtmpfs /dev
for m in $(cat /modules.list); do
  insmod "/mods/$m" 2>/dev/null || echo "vm-init: insmod $m failed"
done
r=/newroot
mount -t 9p -o trans=virtio,version=9p2000.L,ro,msize=262144,cache=loose hostroot $r || {
  echo "vm-init: cannot mount the host root"; poweroff -f; }
mkdir -p /vmwork
mount -t 9p -o trans=virtio,version=9p2000.L,msize=262144 work /vmwork
# Host directories the command needs (its checkout and build, run-vm.sh lists them in "keep")
# that the tmpfs below would hide (a checkout under /tmp or /run): held aside, then bound back
# at their host path on top of the tmpfs.
i=0
while read -r path; do
  [ -d "$r$path" ] || continue
  i=$((i + 1))
  mkdir -p /keep/$i
  mount --bind "$r$path" /keep/$i && echo "$path" > /keep/$i.path
done < /vmwork/keep 2>/dev/null
mount -t tmpfs tmpfs $r/tmp
mount -t tmpfs tmpfs $r/run
for f in /keep/*.path; do
  [ -f "$f" ] || continue
  path=$(cat "$f")
  mkdir -p "$r$path" && mount --bind "${f%.path}" "$r$path" || echo "vm-init: cannot show $path in the guest"
done
mkdir -p $r/tmp/vmwork
mount --bind /vmwork $r/tmp/vmwork
mount --rbind /proc $r/proc
mount --rbind /sys $r/sys
mount --rbind /dev $r/dev
mkdir -p $r/dev/shm $r/dev/pts
mount -t tmpfs tmpfs $r/dev/shm
mount -t devpts devpts $r/dev/pts
ip link set lo up 2>/dev/null
echo "vm-init: up after $(cut -d' ' -f1 /proc/uptime) s, kernel $(uname -r)"
chroot $r /usr/bin/env -i HOME=/root TERM=dumb PATH=/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin \
  /bin/sh /tmp/vmwork/command
echo $? > $r/tmp/vmwork/exit-code
sync
poweroff -f
