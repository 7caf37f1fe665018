//! Section sizes of a firmware image, read from its ELF file: what the flash figures of
//! `qemu --measure` and of one instantiation are made of.

use anyhow::{bail, Context, Result};

/// Image size by ELF section, in bytes.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Sizes {
    /// Allocated read-only sections plus the load image of `.data`: what goes into flash.
    pub flash: u64,
    /// `.data` + `.bss` + `.uninit`: static RAM.
    pub static_ram: u64,
    /// Of which `.text`.
    pub text: u64,
    /// Of which `.rodata`.
    pub rodata: u64,
    /// `.data`.
    pub data: u64,
    /// `.bss` + `.uninit`.
    pub bss: u64,
}

/// Section sizes of a 32-bit little-endian ELF (what `size -A` would print, summed).
pub fn elf_sizes(elf: &[u8]) -> Result<Sizes> {
    let u16_at = |o: usize| -> Result<u64> {
        Ok(u64::from(u16::from_le_bytes(
            elf.get(o..o + 2).context("truncated ELF")?.try_into()?,
        )))
    };
    let u32_at = |o: usize| -> Result<u64> {
        Ok(u64::from(u32::from_le_bytes(
            elf.get(o..o + 4).context("truncated ELF")?.try_into()?,
        )))
    };
    if elf.get(0..4) != Some(b"\x7fELF") || elf.get(4) != Some(&1) || elf.get(5) != Some(&1) {
        bail!("not a 32-bit little-endian ELF");
    }
    let shoff = u32_at(0x20)? as usize;
    let shentsize = u16_at(0x2e)? as usize;
    let shnum = u16_at(0x30)? as usize;
    let shstrndx = u16_at(0x32)? as usize;
    let sh = |i: usize, field: usize| u32_at(shoff + i * shentsize + field);
    let strtab = sh(shstrndx, 0x10)? as usize;
    let name_of = |i: usize| -> Result<String> {
        let start = strtab + sh(i, 0)? as usize;
        let end = elf[start..]
            .iter()
            .position(|&b| b == 0)
            .context("section name")?
            + start;
        Ok(String::from_utf8_lossy(&elf[start..end]).into_owned())
    };
    const SHT_NOBITS: u64 = 8;
    const SHF_WRITE: u64 = 1;
    const SHF_ALLOC: u64 = 2;
    let mut s = Sizes::default();
    for i in 0..shnum {
        let (ty, flags, size) = (sh(i, 4)?, sh(i, 8)?, sh(i, 0x14)?);
        if flags & SHF_ALLOC == 0 {
            continue;
        }
        let name = name_of(i)?;
        // riscv-rt's link.x marks the free RAM as `.heap` and `.stack` (NOLOAD): not statics.
        if name == ".heap" || name == ".stack" {
            continue;
        }
        if ty == SHT_NOBITS {
            s.static_ram += size;
            s.bss += size;
        } else {
            s.flash += size;
            if flags & SHF_WRITE != 0 {
                s.static_ram += size;
                s.data += size;
            }
        }
        match name.as_str() {
            ".text" => s.text += size,
            ".rodata" => s.rodata += size,
            _ => {}
        }
    }
    Ok(s)
}
