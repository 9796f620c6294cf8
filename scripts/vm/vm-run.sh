#!/bin/bash
# Runs one command inside a real Linux kernel under qemu-system (TCG, no KVM needed), with vcan0
# up and a live gpio-sim chip, and returns the command's exit status. The VM sees the host's
# root file system read-only over virtio-9p (so host-built binaries run with their libraries)
# and the current directory read-write. About 8 s per run. Prepare once with prepare.sh.
#
#   scripts/vm/vm-run.sh <command> [args...]
# Environment: MSGRAPHS_VM_DIR (default /opt/msgraphs-vm), VM_TIMEOUT (s), VM_MEM (MiB), VM_SMP.
set -euo pipefail

VM_DIR=${MSGRAPHS_VM_DIR:-/opt/msgraphs-vm}
KROOT=$VM_DIR/kroot
if [ ! -d "$KROOT/lib/modules" ]; then
  echo "vm-run: no prepared kernel in $VM_DIR (run scripts/vm/prepare.sh)" >&2
  exit 125
fi
KVER=$(ls "$KROOT/lib/modules" | head -1)
INITRD=$VM_DIR/initrd-$KVER.cpio.gz

if [ ! -f "$INITRD" ]; then  # 0.3 s, cached
  R=$(mktemp -d)
  mkdir -p "$R"/{bin,proc,sys,dev,host,lib/modules/$KVER}
  cp /bin/busybox "$R/bin/"
  for a in sh mount modprobe chroot poweroff cat mkdir ip sed echo; do ln -s busybox "$R/bin/$a"; done
  cp "$KROOT/lib/modules/$KVER"/modules.* "$R/lib/modules/$KVER/"
  ( cd "$KROOT/lib/modules/$KVER" && find kernel/net/can kernel/drivers/net/can kernel/fs/configfs \
      kernel/fs/9p kernel/net/9p kernel/fs/netfs kernel/fs/fscache kernel/drivers/virtio extra \
      -name '*.ko' 2>/dev/null | cpio -pdm --quiet "$R/lib/modules/$KVER/" )
  cat > "$R/init" <<'INIT'
#!/bin/busybox sh
mount -t proc proc /proc; mount -t sysfs sys /sys; mount -t devtmpfs dev /dev
for m in virtio_pci 9pnet_virtio 9p configfs vcan can-raw gpio-sim; do modprobe $m; done
mount -t 9p -o trans=virtio,version=9p2000.L,ro hostroot /host
mount -t 9p -o trans=virtio,version=9p2000.L job /host/mnt
for d in proc sys dev; do mount --bind /$d /host/$d; done
mount -t tmpfs tmpfs /host/tmp; mount -t tmpfs tmpfs /host/run
mkdir -p /host/dev/shm; mount -t tmpfs tmpfs /host/dev/shm
W=$(cat /host/mnt/cwd); mkdir -p /host$W && mount -t 9p -o trans=virtio,version=9p2000.L work /host$W
mount -t configfs none /host/sys/kernel/config
ip link add dev vcan0 type vcan && ip link set vcan0 up
G=/host/sys/kernel/config/gpio-sim/chip0
mkdir $G $G/bank0 && echo 8 > $G/bank0/num_lines && echo 1 > $G/live
chroot /host /bin/sh -c "cd $W && /bin/sh /mnt/cmd.sh"; rc=$?
echo $rc > /host/mnt/rc; echo "VM-CMD-RC=$rc"; poweroff -f
INIT
  chmod +x "$R/init"
  ( cd "$R" && find . | cpio -o -H newc --quiet | gzip -1 ) > "$INITRD.tmp" && mv "$INITRD.tmp" "$INITRD"
  rm -rf "$R"
fi

JOB=$(mktemp -d); trap 'rm -rf "$JOB"' EXIT
printf '%q ' "$@" > "$JOB/cmd.sh"
pwd > "$JOB/cwd"
timeout "${VM_TIMEOUT:-600}" qemu-system-x86_64 -accel tcg -cpu max -m "${VM_MEM:-1024}" -smp "${VM_SMP:-2}" \
  -nographic -no-reboot -nic none \
  -kernel "$KROOT/boot/vmlinuz-$KVER" -initrd "$INITRD" -append "console=ttyS0 quiet loglevel=3 panic=-1" \
  -virtfs local,path=/,mount_tag=hostroot,security_model=none,readonly=on,multidevs=remap \
  -virtfs local,path="$PWD",mount_tag=work,security_model=none,multidevs=remap \
  -virtfs local,path="$JOB",mount_tag=job,security_model=none,multidevs=remap 2>&1 | tr -d '\r'
if [ -f "$JOB/rc" ]; then exit "$(cat "$JOB/rc")"; fi
echo "vm-run: no exit status from the VM" >&2
exit 125
