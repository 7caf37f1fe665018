//! What differs between the cores the firmware runs on, and nothing else: the instruction
//! counter, the stack pointer and the stack's bounds, a faulting instruction and a delay loop
//! of known length. Everything else (semihosting, defmt, the buffers, the library) is the same
//! code on every core.
//!
//! * Cortex-M (cortex-m-rt): SysTick on the core clock. Under `qemu-system-arm -icount shift=0`
//!   every instruction advances virtual time by exactly 1 ns, so ticks × (1e9 / core clock) is
//!   the number of instructions executed, and it repeats exactly from run to run. The host
//!   converts (it knows each QEMU board's clock, see host-sim/src/qemu.rs).
//! * RISC-V (riscv-rt): the `mcycle` CSR. Under `-icount shift=0` QEMU's `mcycle` (and
//!   `minstret`) read the instruction counter itself, so one tick is one instruction (the
//!   host's board table gives these boards a 1 GHz "clock"); `calibrate` checks it.

#[cfg(target_arch = "arm")]
pub use self::cortex_m_core::*;
#[cfg(target_arch = "riscv32")]
pub use self::riscv_core::*;

#[cfg(target_arch = "arm")]
mod cortex_m_core {
    use core::sync::atomic::{AtomicU32, Ordering};

    use cortex_m::peripheral::{syst::SystClkSource, SCB, SYST};
    use cortex_m_rt::exception;

    /// The timer [`start`] and [`stop`] use.
    pub type Timer = SYST;

    /// The timer, once.
    pub fn timer() -> Option<Timer> {
        cortex_m::Peripherals::take().map(|p| p.SYST)
    }

    const RELOAD: u32 = 0x00FF_FFFF;

    /// SysTick wrap-arounds. Only the SysTick handler writes it (load/store atomics exist on
    /// every Cortex-M, read-modify-write ones not on the M0).
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

    /// Runs a loop of exactly the returned number of instructions: `cortex_m::asm::delay(n)`
    /// runs `subs; bne` n + 1 times.
    #[allow(dead_code)] // the cluster image (src/bin/cluster.rs) shares this file
    pub fn delay(n: u32) -> u32 {
        cortex_m::asm::delay(n);
        2 * (n + 1)
    }

    /// The stack pointer.
    #[inline(always)]
    pub fn stack_pointer() -> usize {
        cortex_m::register::msp::read() as usize
    }

    extern "C" {
        /// Top of the stack (initial MSP), from cortex-m-rt's link.x.
        static _stack_start: u32;
        /// Lowest stack address: the end of .bss/.uninit.
        static _stack_end: u32;
    }

    /// Top of the stack.
    pub fn stack_top() -> usize {
        // Only the address of the linker symbol is taken.
        core::ptr::addr_of!(_stack_start) as usize
    }

    /// Lowest stack address.
    pub fn stack_bottom() -> usize {
        core::ptr::addr_of!(_stack_end) as usize
    }

    /// A permanently undefined instruction: UsageFault escalated to HardFault (M3 and up),
    /// HardFault directly on the M0. (Loads from unmapped addresses do not fault on every QEMU
    /// machine.)
    #[allow(dead_code)] // the cluster image (src/bin/cluster.rs) shares this file
    pub fn fault() -> ! {
        cortex_m::asm::udf()
    }
}

#[cfg(target_arch = "riscv32")]
mod riscv_core {
    /// The cycle counter needs no peripheral: a token, so the firmware reads the same on
    /// every core.
    pub struct Timer {
        start: u64,
    }

    /// The timer, once.
    pub fn timer() -> Option<Timer> {
        Some(Timer { start: 0 })
    }

    /// Starts counting from here.
    pub fn start(t: &mut Timer) {
        t.start = riscv::register::mcycle::read64();
    }

    /// Ticks (instructions under `-icount shift=0`) since [`start`].
    pub fn stop(t: &mut Timer) -> u64 {
        riscv::register::mcycle::read64().wrapping_sub(t.start)
    }

    /// Runs a loop of exactly the returned number of instructions: `addi; bnez` n times
    /// (n ≥ 1).
    #[allow(dead_code)] // the cluster image (src/bin/cluster.rs) shares this file
    pub fn delay(n: u32) -> u32 {
        let n = n.max(1);
        // SAFETY: a register-only countdown loop.
        unsafe {
            core::arch::asm!(
                "2:",
                "addi {0}, {0}, -1",
                "bnez {0}, 2b",
                inout(reg) n => _,
                options(nomem, nostack),
            );
        }
        2 * n
    }

    /// The stack pointer.
    #[inline(always)]
    pub fn stack_pointer() -> usize {
        let sp: usize;
        // SAFETY: reads a register.
        unsafe { core::arch::asm!("mv {}, sp", out(reg) sp, options(nomem, nostack)) };
        sp
    }

    extern "C" {
        /// Top of the stack (the initial SP), from riscv-rt's link.x: the end of the RAM region.
        static _stack_start: u32;
    }

    /// Top of the stack.
    pub fn stack_top() -> usize {
        // Only the address of the linker symbol is taken.
        core::ptr::addr_of!(_stack_start) as usize
    }

    /// Lowest stack address: the end of .bss (riscv-rt's heap starts there and is empty).
    pub fn stack_bottom() -> usize {
        riscv_rt::heap_start() as usize
    }

    /// An illegal instruction (`unimp`): the trap goes to [`ExceptionHandler`].
    #[allow(dead_code)] // the cluster image (src/bin/cluster.rs) shares this file
    pub fn fault() -> ! {
        // SAFETY: traps; the handler exits through semihosting.
        unsafe { core::arch::asm!("unimp", options(noreturn)) }
    }

    /// Every exception (riscv-rt sends the ones without their own handler here): log the cause
    /// and exit with the fault status, as the Cortex-M HardFault handler does.
    #[export_name = "ExceptionHandler"]
    fn exception_handler(_frame: &riscv_rt::TrapFrame) -> ! {
        if !crate::PANICKED.load(core::sync::atomic::Ordering::Relaxed) {
            crate::PANICKED.store(true, core::sync::atomic::Ordering::Relaxed);
            defmt::error!(
                "exception: mcause={=usize:#010x} mepc={=usize:#010x} mtval={=usize:#010x}",
                riscv::register::mcause::read().bits(),
                riscv::register::mepc::read(),
                riscv::register::mtval::read()
            );
        }
        semihosting::process::exit(crate::EXIT_FAULT)
    }

    /// An interrupt: none is enabled, so this is a fault too.
    #[export_name = "DefaultHandler"]
    fn default_handler() {
        defmt::error!(
            "unexpected interrupt: mcause={=usize:#010x}",
            riscv::register::mcause::read().bits()
        );
        semihosting::process::exit(crate::EXIT_FAULT)
    }
}
