#!/usr/bin/env bash
# Builds the files of the test VM from Debian packages: the stock kernel of linux-image-amd64
# (fetched with apt-get download, never installed), the modules the tests load with their
# dependencies, and a busybox initramfs whose /init (tests/vm/init.sh) mounts the host's root
# read-only over 9p and runs one command in it. Usage: build-vm.sh OUT_DIR
# Writes OUT_DIR/{vmlinuz,initramfs.cpio.gz,kernel-version}; does nothing when they are up to date.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
out=${1:?usage: build-vm.sh OUT_DIR}
mkdir -p "$out"
out=$(cd "$out" && pwd)

# The modules the VM tests need (with whatever they depend on); built-in ones are skipped.
modules=(9pnet_virtio 9p virtio_pci fuse cuse uhid hid hid_cp2112)

for tool in busybox cpio depmod modprobe gzip apt-get dpkg-deb; do
  command -v "$tool" >/dev/null || { echo "build-vm: '$tool' is missing (scripts/setup.sh installs it)" >&2; exit 1; }
done
busybox=/bin/busybox  # busybox-static: the initramfs has no libc
[ -x "$busybox" ] || { echo "build-vm: /bin/busybox is missing (package busybox-static)" >&2; exit 1; }

package=$(apt-cache depends linux-image-amd64 2>/dev/null | awk '/Depends: linux-image-[0-9]/{print $2; exit}')
[ -n "$package" ] || { echo "build-vm: apt knows no linux-image-amd64 (run apt-get update)" >&2; exit 1; }
stamp="$package $(sha256sum "$here/build-vm.sh" "$here/init.sh" | sha256sum | cut -c1-16)"
if [ -f "$out/stamp" ] && [ "$(cat "$out/stamp")" = "$stamp" ] && [ -f "$out/initramfs.cpio.gz" ] && [ -f "$out/vmlinuz" ]; then
  exit 0
fi

deb=$(ls "$out"/"$package"_*.deb 2>/dev/null | head -n1 || true)
if [ -z "$deb" ]; then
  echo "build-vm: apt-get download $package"
  (cd "$out" && apt-get download "$package" 2>&1 | grep -v "^W: Download is performed unsandboxed" >&2 || true)
  deb=$(ls "$out"/"$package"_*.deb 2>/dev/null | head -n1 || true)
  [ -n "$deb" ] || { echo "build-vm: could not download $package" >&2; exit 1; }
fi

root="$out/kernel-root"
rm -rf "$root"
mkdir -p "$root"
dpkg-deb -x "$deb" "$root"
version=$(ls "$root/lib/modules" 2>/dev/null || ls "$root/usr/lib/modules")
moddir="$root/lib/modules/$version"
[ -d "$moddir" ] || moddir="$root/usr/lib/modules/$version"
depmod -b "$root" "$version" 2>/dev/null || depmod -b "$root/usr" "$version"
cp "$root/boot/vmlinuz-$version" "$out/vmlinuz"

initrd="$out/initrd"
rm -rf "$initrd"
mkdir -p "$initrd"/{bin,dev,proc,sys,mods,newroot}
cp "$busybox" "$initrd/bin/busybox"
cp "$here/init.sh" "$initrd/init"
chmod +x "$initrd/init"
: > "$initrd/modules.list"
for m in "${modules[@]}"; do
  while read -r kind path _; do
    [ "$kind" = insmod ] || continue
    name=$(basename "$path")
    name=${name%.xz}
    name=${name%.zst}
    grep -qx "$name" "$initrd/modules.list" && continue
    case "$path" in
      *.xz) xz -dc "$path" > "$initrd/mods/$name" ;;
      *.zst) zstd -qdc "$path" > "$initrd/mods/$name" ;;
      *) cp "$path" "$initrd/mods/$name" ;;
    esac
    echo "$name" >> "$initrd/modules.list"
  done < <(modprobe -d "$root" -S "$version" --show-depends "$m" 2>/dev/null || true)
done
cp "$initrd/modules.list" "$out/modules.list"
(cd "$initrd" && find . | cpio -o -H newc --quiet | gzip -1) > "$out/initramfs.cpio.gz"
rm -rf "$initrd" "$root"
echo "$version" > "$out/kernel-version"
echo "$stamp" > "$out/stamp"
echo "build-vm: kernel $version with $(wc -l < "$out/modules.list") modules in $out"
