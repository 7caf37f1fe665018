//! Measurements around the simplification: emulated time through the core's counter
//! ([`start`], [`stop`]: SysTick on Cortex-M, `mcycle` on RISC-V, see src/arch.rs; the host
//! converts ticks to instructions), and the stack high-water mark by painting the free stack
//! before and scanning it after.

use crate::arch::{stack_bottom, stack_pointer, stack_top};
pub use crate::arch::{start, stop};

const PAINT: u32 = 0x5A5A_C3C3;

/// Fills the unused stack, from its lowest address to just below this function's frame, with
/// a pattern. Returns the caller's stack pointer.
#[inline(never)]
pub fn paint() -> usize {
    let sp = stack_pointer();
    let mut p = stack_bottom();
    let end = sp.saturating_sub(16) & !3;
    while p < end {
        // SAFETY: [stack_bottom, sp - 16) is unused stack memory between .bss and the live
        // frames; nothing else refers to it.
        unsafe { core::ptr::write_volatile(p as *mut u32, PAINT) };
        p += 4;
    }
    sp
}

/// The lowest stack address written since [`paint`].
pub fn lowest_touched() -> usize {
    let mut p = stack_bottom();
    let top = stack_top();
    // SAFETY: reads of the stack region only.
    while p < top && unsafe { core::ptr::read_volatile(p as *const u32) } == PAINT {
        p += 4;
    }
    p
}

/// Stack bytes from the top of the stack down to `addr`.
pub fn depth(addr: usize) -> usize {
    stack_top().saturating_sub(addr)
}

/// Bytes of stack the board has at all (RAM left after .data, .bss and .uninit).
pub fn stack_size() -> usize {
    stack_top() - stack_bottom()
}

#[cfg_attr(not(feature = "lib"), allow(dead_code))]
/// Whether the stack reached its lowest word (it may then have run into .bss unnoticed).
pub fn overflowed(lowest: usize) -> bool {
    lowest <= stack_bottom()
}
