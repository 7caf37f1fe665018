//! Measurements around the simplification: emulated time through SysTick, and the stack
//! high-water mark by painting the free stack before and scanning it after.
//!
//! SysTick runs from the core clock. Under `qemu-system-arm -icount shift=0` every instruction
//! advances virtual time by exactly 1 ns, so ticks × (1e9 / core clock) is the number of
//! instructions executed, and it repeats exactly from run to run. The host converts (it knows
//! each QEMU board's clock, see host-sim/src/qemu.rs); the firmware only counts ticks.

use core::sync::atomic::{AtomicU32, Ordering};

use cortex_m::peripheral::{syst::SystClkSource, SCB, SYST};
use cortex_m_rt::exception;

const RELOAD: u32 = 0x00FF_FFFF;

/// SysTick wrap-arounds. Only the SysTick handler writes it (load/store atomics exist on every
/// Cortex-M, read-modify-write ones not on the M0).
static WRAPS: AtomicU32 = AtomicU32::new(0);

#[exception]
fn SysTick() {
    WRAPS.store(
        WRAPS.load(Ordering::Relaxed).wrapping_add(1),
        Ordering::Relaxed,
    );
}

/// Starts SysTick from zero.
pub fn start(syst: &mut SYST) {
    syst.disable_counter();
    syst.set_clock_source(SystClkSource::Core);
    syst.set_reload(RELOAD);
    syst.clear_current();
    WRAPS.store(0, Ordering::Relaxed);
    syst.enable_interrupt();
    syst.enable_counter();
}

/// Stops SysTick; ticks since [`start`].
pub fn stop(syst: &mut SYST) -> u64 {
    syst.disable_counter();
    let current = SYST::get_current();
    let mut wraps = u64::from(WRAPS.load(Ordering::Relaxed));
    if SCB::is_pendst_pending() {
        // Wrapped after the last handler ran: count it, and drop the pending exception.
        wraps += 1;
        SCB::clear_pendst();
    }
    syst.disable_interrupt();
    // After `clear_current` the counter reads 0; the first tick loads RELOAD, and each wrap
    // (RELOAD + 1 ticks) ends on 0, which is when the exception is raised. So at tick t the
    // counter reads RELOAD + 1 - t mod (RELOAD + 1), with 0 meaning "just wrapped".
    let period = u64::from(RELOAD) + 1;
    let current = u64::from(current.min(RELOAD));
    if current == 0 {
        wraps * period
    } else {
        wraps * period + (period - current)
    }
}

const PAINT: u32 = 0x5A5A_C3C3;

extern "C" {
    /// Top of the stack (initial MSP), from cortex-m-rt's link.x.
    static _stack_start: u32;
    /// Lowest stack address: the end of .bss/.uninit.
    static _stack_end: u32;
}

fn stack_top() -> usize {
    // Only the address of the linker symbol is taken.
    core::ptr::addr_of!(_stack_start) as usize
}

fn stack_bottom() -> usize {
    core::ptr::addr_of!(_stack_end) as usize
}

/// Fills the unused stack, from its lowest address to just below this function's frame, with
/// a pattern. Returns the caller's stack pointer.
#[inline(never)]
pub fn paint() -> usize {
    let sp = cortex_m::register::msp::read() as usize;
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
