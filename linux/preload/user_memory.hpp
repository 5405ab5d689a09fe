// Copies between the host program's memory and the emulator with the kernel's EFAULT instead
// of a crash: a pointer is checked with process_vm_readv/writev the first time its pages are
// seen (pages that passed are remembered per thread, so steady-state copies are plain memcpy).
// Memory unmapped after it passed once is not re-checked: a program that hands freed
// mappings to an ioctl may crash where the kernel would say EFAULT.
#pragma once

#include <cstddef>

namespace l6470emu::preload {

/// Copies `n` bytes from host memory `src`; false (nothing copied) if the kernel would say EFAULT.
bool copy_from_user(void* dst, const void* src, std::size_t n);
/// Copies `n` bytes to host memory `dst`; false if the kernel would say EFAULT.
bool copy_to_user(void* dst, const void* src, std::size_t n);
/// Forgets the remembered pages (after fork, munmap of interest).
void forget_user_pages();

}  // namespace l6470emu::preload
