// Homing against a limit switch from Go, as examples/run/homing.c does it from C: GoUntil in
// reverse until the switch closes, ReleaseSW forward until it opens (ABS_POS becomes 0 there).
// Go's runtime makes its system calls itself, not through libc, so no LD_PRELOAD reaches this
// program: `l6470emu run --nodes kernel` serves it on the kernel's own /dev/spidev0.0 (the VM
// test, tests/vm/kernel_nodes_guest.sh). Standard library only; built with CGO_ENABLED=0, static.
package main

import (
	"fmt"
	"os"
	"syscall"
	"time"
	"unsafe"
)

// linux/spi/spidev.h, as _IOW('k', nr, size) spells them on x86-64.
const (
	spiIocWrMode              = 0x40016b01 // _IOW('k', 1, __u8)
	spiIocWrMaxSpeedHz        = 0x40046b04 // _IOW('k', 4, __u32)
	spiIocMessageOne          = 0x40206b00 // SPI_IOC_MESSAGE(1): one struct spi_ioc_transfer of 32 bytes
	spiMode3                  = 3
	speedHz            uint32 = 1000000
)

// struct spi_ioc_transfer (32 bytes).
type transfer struct {
	txBuf, rxBuf                     uint64
	length, speedHz                  uint32
	delayUsecs                       uint16
	bitsPerWord, csChange, txNbits   uint8
	rxNbits, wordDelayUsecs, padding uint8
}

var fd uintptr

func ioctl(request uintptr, arg unsafe.Pointer) error {
	if _, _, errno := syscall.Syscall(syscall.SYS_IOCTL, fd, request, uintptr(arg)); errno != 0 {
		return errno
	}
	return nil
}

func must(err error, what string) {
	if err != nil {
		fmt.Fprintf(os.Stderr, "homing: %s: %v\n", what, err)
		os.Exit(2)
	}
}

// exchange sends one byte in a chip-select frame of its own and returns the byte shifted out.
func exchange(out byte) byte {
	var in byte
	t := transfer{txBuf: uint64(uintptr(unsafe.Pointer(&out))), rxBuf: uint64(uintptr(unsafe.Pointer(&in))), length: 1}
	must(ioctl(spiIocMessageOne, unsafe.Pointer(&t)), "SPI_IOC_MESSAGE")
	return in
}

// command sends an opcode and n argument bytes (most significant first); returns the last n answer bytes.
func command(op byte, arg uint32, n int) uint32 {
	var answer uint32
	exchange(op)
	for i := n - 1; i >= 0; i-- {
		answer = answer<<8 | uint32(exchange(byte(arg>>(8*uint(i)))))
	}
	return answer
}

func status() uint16 { return uint16(command(0xD0, 0, 2)) } // GetStatus

func absPos() int32 { // GetParam(ABS_POS): 22 bits, two's complement
	v := int32(command(0x21, 0, 3) & 0x3FFFFF)
	if v&0x200000 != 0 {
		v -= 1 << 22
	}
	return v
}

// waitIdle polls GetStatus until BUSY (bit 1, active low) reads high, every millisecond.
func waitIdle(limit time.Duration) bool {
	for start := time.Now(); time.Since(start) < limit; time.Sleep(time.Millisecond) {
		if status()&0x0002 != 0 {
			return true
		}
	}
	return false
}

func main() {
	f, err := os.OpenFile("/dev/spidev0.0", os.O_RDWR, 0)
	must(err, "open /dev/spidev0.0")
	defer f.Close()
	fd = f.Fd()
	mode := uint8(spiMode3)
	must(ioctl(spiIocWrMode, unsafe.Pointer(&mode)), "SPI_IOC_WR_MODE")
	speed := speedHz
	must(ioctl(spiIocWrMaxSpeedHz, unsafe.Pointer(&speed)), "SPI_IOC_WR_MAX_SPEED_HZ")

	status()                // the power-up UVLO latch released
	command(0x82, 13422, 3) // GoUntil(ACT = 0, reverse) at 200 step/s: 200 * 2^28 / 4 MHz
	if !waitIdle(60 * time.Second) {
		fmt.Fprintln(os.Stderr, "homing: GoUntil never ended")
		os.Exit(1)
	}
	command(0x93, 0, 0) // ReleaseSW(ACT = 0, forward)
	if !waitIdle(60 * time.Second) {
		fmt.Fprintln(os.Stderr, "homing: ReleaseSW never ended")
		os.Exit(1)
	}
	fmt.Printf("homed: ABS_POS %d\n", absPos())
}
