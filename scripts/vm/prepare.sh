#!/bin/bash
# One-time preparation of the kernel-in-the-loop VM (docs/kernel-in-the-loop.md): a stock Debian
# kernel with vcan and can-raw, plus gpio-sim and irq_sim built out of tree from Debian's own
# kernel source (Debian 6.1 does not build them). Everything comes from the Debian mirror.
# Idempotent: a stamp file records the kernel it was built for. About 40 s on a fresh machine.
#
#   scripts/vm/prepare.sh            # into ${MSGRAPHS_VM_DIR:-/opt/msgraphs-vm}
set -euo pipefail

VM_DIR=${MSGRAPHS_VM_DIR:-/opt/msgraphs-vm}
SUDO=""; [ "$(id -u)" -ne 0 ] && SUDO="sudo"

need=()
for p in qemu-system-x86 busybox-static kmod cpio make gcc bc; do
  dpkg -s "$p" >/dev/null 2>&1 || need+=("$p")
done
if [ ${#need[@]} -gt 0 ]; then
  $SUDO apt-get update -qq
  $SUDO env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends "${need[@]}"
fi

# The kernel ABI name changes with Debian point releases: derive it, never hard-code it.
KPKG=$(apt-cache depends linux-image-amd64 | awk '/Depends: linux-image-/{print $2; exit}')
KVER=${KPKG#linux-image-}
STAMP="$VM_DIR/.prepared-$KVER"
if [ -f "$STAMP" ]; then
  echo "vm: kernel $KVER already prepared in $VM_DIR"
  exit 0
fi
dpkg -s "linux-headers-$KVER" >/dev/null 2>&1 || \
  $SUDO env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends "linux-headers-$KVER"

$SUDO mkdir -p "$VM_DIR"
$SUDO chown "$(id -u):$(id -g)" "$VM_DIR"
WORK=$(mktemp -d); trap 'rm -rf "$WORK"' EXIT
cd "$WORK"
apt-get download "$KPKG" linux-source-6.1 >/dev/null
rm -rf "$VM_DIR/kroot"
dpkg-deb -x "${KPKG}"_*.deb "$VM_DIR/kroot"
dpkg-deb --fsys-tarfile linux-source-6.1_*.deb | tar -x ./usr/src/linux-source-6.1.tar.xz
tar -xJf usr/src/linux-source-6.1.tar.xz --wildcards \
  'linux-source-6.1/drivers/gpio/gpio-sim.c' 'linux-source-6.1/drivers/gpio/gpiolib.h' \
  'linux-source-6.1/kernel/irq/irq_sim.c'
mkdir gpiomod
cp linux-source-6.1/drivers/gpio/{gpio-sim.c,gpiolib.h} linux-source-6.1/kernel/irq/irq_sim.c gpiomod/
# irq_to_desc is not exported to modules in 6.1; the safe generic handler is.
sed -i 's/handle_simple_irq(irq_to_desc(irqnum));/generic_handle_irq_safe(irqnum);/' gpiomod/irq_sim.c
printf '\nMODULE_LICENSE("GPL");\n' >> gpiomod/irq_sim.c
printf 'obj-m += irq_sim.o gpio-sim.o\n' > gpiomod/Kbuild
make -s -C "/lib/modules/$KVER/build" M="$PWD/gpiomod" modules
mkdir -p "$VM_DIR/kroot/lib/modules/$KVER/extra"
cp gpiomod/*.ko "$VM_DIR/kroot/lib/modules/$KVER/extra/"
depmod -b "$VM_DIR/kroot" "$KVER"   # the .deb ships no modules.dep
rm -f "$VM_DIR"/.prepared-* "$VM_DIR"/initrd-*.cpio.gz
touch "$STAMP"
echo "vm: prepared kernel $KVER in $VM_DIR"
