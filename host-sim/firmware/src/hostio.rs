//! Host files through semihosting (SYS_OPEN/READ/WRITE/CLOSE, SYS_GET_CMDLINE). Only the
//! `semihosting` crate's file API is used here; its stdout belongs to defmt-semihosting, and a
//! raw print there would corrupt the defmt frames.

use core::ffi::CStr;

use semihosting::fs::File;
use semihosting::io::{Read, Write};

/// Up to three command-line words (program, case file, result file), as given to QEMU with
/// `-semihosting-config enable=on,target=native,arg=<prog>,arg=<case>,arg=<out>`.
pub struct Args {
    buf: [u8; 256],
    starts: [usize; 3],
    ends: [usize; 3],
    pub count: usize,
}

impl Args {
    pub fn get(&self, i: usize) -> Option<&str> {
        if i >= self.count {
            return None;
        }
        core::str::from_utf8(self.buf.get(self.starts[i]..self.ends[i])?).ok()
    }
}

/// Reads the command line. Arguments are separated by spaces (paths must not contain any).
/// Never inlined: the semihosting crate's own 256-byte copy stays out of `main`'s frame.
#[inline(never)]
pub fn args() -> Args {
    let mut a = Args {
        buf: [0; 256],
        starts: [0; 3],
        ends: [0; 3],
        count: 0,
    };
    let Ok(args) = semihosting::experimental::env::args::<256>() else {
        return a;
    };
    let mut at = 0;
    for word in (&args).flatten() {
        if a.count == 3 || at + word.len() > a.buf.len() {
            break;
        }
        a.buf[at..at + word.len()].copy_from_slice(word.as_bytes());
        a.starts[a.count] = at;
        a.ends[a.count] = at + word.len();
        a.count += 1;
        at += word.len();
    }
    a
}

/// A NUL-terminated copy of a path.
pub struct CPath([u8; 128]);

impl CPath {
    pub fn new(path: &str) -> Option<Self> {
        let mut b = [0u8; 128];
        if path.len() >= b.len() || path.as_bytes().contains(&0) {
            return None;
        }
        b[..path.len()].copy_from_slice(path.as_bytes());
        Some(CPath(b))
    }
    pub fn as_cstr(&self) -> &CStr {
        CStr::from_bytes_until_nul(&self.0).unwrap_or(c"")
    }
}

#[derive(Clone, Copy, Debug, defmt::Format)]
pub enum IoError {
    Path,
    Open,
    Read,
    Write,
}

#[inline(never)]
pub fn open(path: &str) -> Result<File, IoError> {
    let p = CPath::new(path).ok_or(IoError::Path)?;
    File::open(p.as_cstr()).map_err(|_| IoError::Open)
}

#[inline(never)]
pub fn create(path: &str) -> Result<File, IoError> {
    let p = CPath::new(path).ok_or(IoError::Path)?;
    File::create(p.as_cstr()).map_err(|_| IoError::Open)
}

/// The first four bytes of a file (shorter files: zero-padded).
#[allow(dead_code)] // the cluster image (src/bin/cluster.rs) shares this file
#[inline(never)]
pub fn magic(path: &str) -> Result<[u8; 4], IoError> {
    let mut f = open(path)?;
    let mut m = [0u8; 4];
    let mut at = 0;
    while at < m.len() {
        let n = read_some(&mut f, m.get_mut(at..).unwrap_or(&mut []))?;
        if n == 0 {
            break;
        }
        at += n;
    }
    Ok(m)
}

/// Reads what is there, up to `buf.len()` bytes; 0 at the end of the file.
#[allow(dead_code)] // the cluster image (src/bin/cluster.rs) shares this file
pub fn read_some(f: &mut File, buf: &mut [u8]) -> Result<usize, IoError> {
    f.read(buf).map_err(|_| IoError::Read)
}

pub fn read_exact(f: &mut File, buf: &mut [u8]) -> Result<(), IoError> {
    f.read_exact(buf).map_err(|_| IoError::Read)
}

pub fn write_all(f: &mut File, buf: &[u8]) -> Result<(), IoError> {
    f.write_all(buf).map_err(|_| IoError::Write)
}
