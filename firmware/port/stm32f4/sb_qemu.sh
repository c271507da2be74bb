#!/bin/sh
# Runs a board image of the qemu-stm32f4 port in qemu-system-arm's
# netduinoplus2 (an STM32F405), taking what the boards' native programs take:
#
#   sb_qemu.sh IMAGE.elf [--host-fd N] [--plant-fd N] [--boot HEX]
#
# USART1, the host's line: the inherited socket --host-fd, else a new pty,
# which QEMU names on stdout ("char device redirected to /dev/pts/N (label
# serial0)").  USART2, the plant link: the inherited socket --plant-fd, else
# nothing.  The boot id (Owner.boot): --boot, else 4 random bytes, written
# by QEMU's loader at the image's sb_boot_seed before reset.  SIGTERM ends it.
set -eu
usage() {
    echo "sb_qemu.sh: $1; usage: sb_qemu.sh IMAGE.elf [--host-fd N] [--plant-fd N] [--boot HEX]" >&2
    exit 2
}
[ $# -ge 1 ] || usage "no image"
elf=$1
shift
host="-serial pty"
plant="-serial null"
boot=""
while [ $# -gt 0 ]; do
    [ $# -ge 2 ] || usage "$1 takes a value"
    case "$1:$2" in
    --host-fd:*[!0-9]* | --plant-fd:*[!0-9]*) usage "$1 takes a descriptor" ;;
    --host-fd:*) host="-chardev socket,id=host,fd=$2 -serial chardev:host" ;;
    --plant-fd:*) plant="-chardev socket,id=plant,fd=$2 -serial chardev:plant" ;;
    --boot:*) boot=$2 ;;
    *) usage "unknown argument $1" ;;
    esac
    shift 2
done
seed=$(arm-none-eabi-nm "$elf" | awk '$3 == "sb_boot_seed" { print $1 }')
[ -n "$seed" ] || usage "$elf has no sb_boot_seed"
[ -n "$boot" ] || boot=$(od -An -N4 -tx4 /dev/urandom | tr -d ' \n')
[ "$((0x$boot))" -ne 0 ] || boot=1
# shellcheck disable=SC2086 # $host and $plant are QEMU options, split on purpose
exec qemu-system-arm -M netduinoplus2 -nographic -monitor none $host $plant \
    -kernel "$elf" -device "loader,addr=0x$seed,data=0x$boot,data-len=4"
