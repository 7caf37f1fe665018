//! `tinydecimate embed INPUT OUTPUT`: a mesh file as Rust source for firmware (`pub static
//! POSITIONS` and `pub static TRIANGLES`, so the mesh sits in flash), or with `--blob` as a
//! binary file for `include_bytes!`.
//!
//! Coordinates are written with `{:?}`: the shortest decimal that reads back as the same `f32`
//! (`-0.0` included). rustc reads an `f32` literal with the same correctly rounded algorithm
//! as `str::parse::<f32>` (it asserts that the two agree), so the `static` holds the file's
//! bits exactly; `f32::from_bits(0x…)` would be as exact and unreadable.
//!
//! Vertices keep the file's numbering, unused ones included, as the loader keeps them; every
//! position must be finite (the loader already refuses a non-finite vertex a triangle uses;
//! a non-finite unused one is refused here, as a literal cannot hold it).
//!
//! The blob (`--blob`), all little-endian, each part starting at a multiple of 4 bytes:
//!
//! | offset | bytes | what |
//! |---|---|---|
//! | 0 | 4 | magic `TDM1` |
//! | 4 | 4 | vertex count V, u32 |
//! | 8 | 4 | triangle count T, u32 |
//! | 12 | 4 | bytes per index, u32: 2 or 4 |
//! | 16 | 12 V | positions, `[f32; 3]` each |
//! | 16 + 12 V | 3 T × (2 or 4) | triangles, three indices each |
//!
//! `include_bytes!` gives a `&[u8; N]` aligned to 1 byte: decode it with `from_le_bytes`, or
//! wrap it in a `#[repr(C, align(4))]` struct before viewing the parts as `f32`/`u16`/`u32`
//! slices in place.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};

use crate::io::{self, MeshData};

/// The blob's first four bytes (the last one is the layout's version).
pub const BLOB_MAGIC: [u8; 4] = *b"TDM1";

/// Bytes before the positions in a blob.
pub const BLOB_HEADER_BYTES: usize = 16;

/// `tinydecimate embed INPUT OUTPUT`
#[derive(Clone, Debug, clap::Args)]
pub struct Args {
    /// The mesh file (OBJ, PLY, STL or glTF; `-`: standard input).
    pub input: PathBuf,
    /// The Rust source to write (`-`: standard output), or the blob with --blob.
    pub output: PathBuf,
    /// Index type of TRIANGLES: auto is u16 when there are at most 65 535 vertices (the
    /// library reserves u16::MAX), else u32.
    #[arg(long, value_enum, default_value_t = IndexArg::Auto)]
    pub index: IndexArg,
    /// Write a little-endian binary blob for `include_bytes!` instead of Rust source (layout
    /// in docs/harness.md).
    #[arg(long)]
    pub blob: bool,
}

/// `--index`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum IndexArg {
    /// u16 when the vertex count allows it, else u32.
    Auto,
    /// u16: at most 65 535 vertices.
    U16,
    /// u32.
    U32,
}

/// The index type written.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Width {
    /// 2 bytes.
    U16,
    /// 4 bytes.
    U32,
}

impl Width {
    fn name(self) -> &'static str {
        match self {
            Width::U16 => "u16",
            Width::U32 => "u32",
        }
    }
}

/// The index type for `vertices` vertices under `arg`: indices must stay below the type's
/// largest value, which the library reserves as "none".
pub fn width(arg: IndexArg, vertices: usize) -> Result<Width> {
    let fits16 = vertices <= usize::from(u16::MAX);
    let fits32 = u32::try_from(vertices).is_ok_and(|v| v < u32::MAX);
    match arg {
        IndexArg::U16 if !fits16 => {
            bail!("{vertices} vertices do not fit u16 indices (at most 65 535): use --index u32")
        }
        IndexArg::U16 => Ok(Width::U16),
        _ if !fits32 => bail!("{vertices} vertices do not fit u32 indices"),
        IndexArg::Auto if fits16 => Ok(Width::U16),
        IndexArg::Auto | IndexArg::U32 => Ok(Width::U32),
    }
}

/// Refuses a mesh a `static` cannot hold: a non-finite coordinate (1-based vertex number, as
/// the loader's messages count).
pub fn check_finite(mesh: &MeshData) -> Result<()> {
    if let Some((i, p)) = mesh
        .positions
        .iter()
        .enumerate()
        .find(|(_, p)| p.iter().any(|c| !c.is_finite()))
    {
        bail!(
            "vertex {} is [{:?}, {:?}, {:?}]: positions must be finite",
            i + 1,
            p[0],
            p[1],
            p[2]
        );
    }
    Ok(())
}

/// A path as the regenerating command spells it: bare when it is plain, else single-quoted
/// for a POSIX shell.
fn shell_word(p: &Path) -> String {
    let s = p.to_string_lossy();
    let plain = !s.is_empty()
        && s.chars()
            .all(|c| c.is_ascii_alphanumeric() || "-_./+=:,@%".contains(c));
    if plain {
        s.into_owned()
    } else {
        format!("'{}'", s.replace('\'', r"'\''"))
    }
}

/// The command that writes this output again.
fn command(args: &Args) -> String {
    let mut c = format!(
        "tinydecimate embed {} {}",
        shell_word(&args.input),
        shell_word(&args.output)
    );
    match args.index {
        IndexArg::Auto => {}
        IndexArg::U16 => c += " --index u16",
        IndexArg::U32 => c += " --index u32",
    }
    if args.blob {
        c += " --blob";
    }
    c
}

/// The Rust source: a comment header naming `source` and `command`, the counts, then the two
/// `static`s, one vertex or triangle per line.
pub fn rust_source(mesh: &MeshData, width: Width, source: &str, command: &str) -> String {
    let (v, t) = (mesh.positions.len(), mesh.triangles.len());
    let mut s = String::with_capacity(40 * v + 24 * t + 2048);
    // Plain comments, not `//!`: the file can then also be pulled in with `include!`.
    let _ = write!(
        s,
        "// The mesh of {source} for firmware: {v} vertices, {t} triangles, {w} indices.\n\
         // Generated by the tinydecimate command line; do not edit. Regenerate with\n\
         //   {command}\n\
         // (in the tinydecimate repository: cargo run -p tinydecimate-cli --release -- embed ...).\n\
         // Vertices keep the file's numbering; each coordinate literal reads back as the file's\n\
         // f32, bit for bit.\n\
         \n\
         /// Vertices in [`POSITIONS`].\n\
         pub const VERTICES: usize = {v};\n\
         /// Triangles in [`TRIANGLES`].\n\
         pub const TRIANGLES_COUNT: usize = {t};\n\
         \n\
         /// Positions `[x, y, z]`: a `static`, so in flash; the simplifier only reads them.\n\
         #[rustfmt::skip]\n\
         #[allow(clippy::approx_constant, clippy::excessive_precision, clippy::unreadable_literal)]\n\
         pub static POSITIONS: [[f32; 3]; VERTICES] = [\n",
        w = width.name()
    );
    for p in &mesh.positions {
        let _ = writeln!(s, "    [{:?}, {:?}, {:?}],", p[0], p[1], p[2]);
    }
    let _ = write!(
        s,
        "];\n\
         \n\
         /// Triangles, indices into [`POSITIONS`] in the file's order and winding. The simplifier\n\
         /// rewrites triangles in place: copy these into a buffer in RAM first.\n\
         #[rustfmt::skip]\n\
         #[allow(clippy::unreadable_literal)]\n\
         pub static TRIANGLES: [[{w}; 3]; TRIANGLES_COUNT] = [\n",
        w = width.name()
    );
    for tri in &mesh.triangles {
        let _ = writeln!(s, "    [{}, {}, {}],", tri[0], tri[1], tri[2]);
    }
    s += "];\n";
    s
}

/// The blob: header, positions, triangles (the layout in this module's documentation).
pub fn blob(mesh: &MeshData, width: Width) -> Vec<u8> {
    let (v, t) = (mesh.positions.len(), mesh.triangles.len());
    let index_bytes: u32 = match width {
        Width::U16 => 2,
        Width::U32 => 4,
    };
    let mut b = Vec::with_capacity(BLOB_HEADER_BYTES + 12 * v + 3 * 4 * t);
    b.extend_from_slice(&BLOB_MAGIC);
    // `width` has checked that the vertex count fits a u32; a triangle count beyond it would
    // need 48 GiB of input.
    for n in [v as u32, t as u32, index_bytes] {
        b.extend_from_slice(&n.to_le_bytes());
    }
    for p in &mesh.positions {
        for c in p {
            b.extend_from_slice(&c.to_le_bytes());
        }
    }
    for tri in &mesh.triangles {
        for &i in tri {
            match width {
                // `width` has checked that every index fits.
                Width::U16 => b.extend_from_slice(&(i as u16).to_le_bytes()),
                Width::U32 => b.extend_from_slice(&i.to_le_bytes()),
            }
        }
    }
    b
}

/// `tinydecimate embed`.
pub fn run(args: &Args) -> Result<std::process::ExitCode> {
    let source = if io::is_std(&args.input) {
        "standard input".to_string()
    } else {
        args.input.display().to_string()
    };
    for p in [&args.input, &args.output] {
        if p.to_string_lossy().chars().any(char::is_control) {
            bail!(
                "{:?}: a control character in a path cannot go into the header",
                p
            );
        }
    }
    if io::same_file(&args.input, &args.output) {
        bail!(
            "{}: is the input; write the output elsewhere",
            args.output.display()
        );
    }
    let mesh = io::load_noting(&args.input)?;
    check_finite(&mesh).with_context(|| source.clone())?;
    if u32::try_from(mesh.triangles.len()).is_err() {
        bail!(
            "{source}: {} triangles do not fit a u32 count",
            mesh.triangles.len()
        );
    }
    let width = width(args.index, mesh.positions.len()).with_context(|| source.clone())?;
    let bytes = if args.blob {
        blob(&mesh, width)
    } else {
        rust_source(&mesh, width, &source, &command(args)).into_bytes()
    };
    if io::is_std(&args.output) {
        let mut out = std::io::stdout().lock();
        std::io::Write::write_all(&mut out, &bytes)
            .and_then(|()| std::io::Write::flush(&mut out))
            .context("standard output: cannot write")?;
    } else {
        std::fs::write(&args.output, &bytes)
            .with_context(|| format!("{}: cannot write", args.output.display()))?;
        crate::outln!(
            "{}: {} vertices, {} triangles, {} indices, {} bytes",
            args.output.display(),
            mesh.positions.len(),
            mesh.triangles.len(),
            width.name(),
            bytes.len()
        );
    }
    Ok(std::process::ExitCode::SUCCESS)
}
