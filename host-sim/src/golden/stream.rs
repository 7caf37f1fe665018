//! Golden cases of progressive streams: the `[[stream]]` entries of `tests/golden/cases.toml`.
//!
//! Each names a mesh (as a `[[case]]` does), how to encode it (base ratio, quantised or f32
//! positions, chunk payload) and optionally a corruption (cut short, or one bit flipped). The
//! host encodes it with the library (so the stream follows the math backend, like every golden),
//! then the stream is decoded by `meshfmt::pm::run` (in memory on the host, through
//! semihosting on each board, fed in pieces of 1 to 128 bytes): the meshes as it refines, the
//! final mesh and positions, and the slider down to the base mesh and back. The output must be
//! the golden `<backend>/<name>.bin` byte for byte (its trailer's measurement block zeroed);
//! `<backend>/<name>.txt` says what is in it.

use std::fmt::Write as _;
use std::path::Path;

use anyhow::{bail, Result};
use meshfmt::pm::{self, Record, Summary, Tag};
use serde::Deserialize;
use tinydecimate::Config;

use crate::backend::Backend;
use crate::golden::{self, sha256_hex, Golden, Verdict};
use crate::io::MeshData;

/// One `[[stream]]` of the manifest.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct StreamSpec {
    /// Golden file name.
    pub name: String,
    /// What the case checks.
    #[serde(default)]
    pub about: String,
    /// A generator (`icosphere 1`) or a mesh file under `tests/`.
    pub mesh: String,
    /// Base mesh as a fraction of the input's triangles (`Config::new().with_ratio`).
    pub base_ratio: f32,
    /// 16-bit quantised positions.
    #[serde(default)]
    pub quantised: bool,
    /// Largest chunk payload, bytes.
    #[serde(default = "default_chunk")]
    pub chunk: u16,
    /// Keep only this fraction of the stream's bytes (a cut link).
    #[serde(default)]
    pub truncate: Option<f32>,
    /// Flip this bit of the stream (bit `k % (8 × bytes)`, least significant first).
    #[serde(default)]
    pub flip_bit: Option<u64>,
}

fn default_chunk() -> u16 {
    256
}

/// A stream case, encoded.
#[derive(Clone, Debug)]
pub struct StreamCase {
    /// Its manifest entry.
    pub spec: StreamSpec,
    /// The stream as the device receives it (corruption applied).
    pub stream: Vec<u8>,
    /// Vertices and triangles of the full mesh (from the stream's header).
    pub vertices: usize,
    /// See `vertices`.
    pub triangles: usize,
}

/// Host storage for the reference run: larger than any board's.
const HOST_VERTICES: usize = 1 << 16;
const HOST_TRIANGLES: usize = 1 << 17;
const HOST_BUFFER: usize = 65_535 + tinydecimate::stream::CHUNK_OVERHEAD;

impl StreamCase {
    /// Encodes the stream a manifest entry describes, with this build's math backend.
    pub fn from_spec(spec: &StreamSpec) -> Result<Self> {
        let m = golden::load_mesh(&spec.name, &spec.mesh)?;
        let mesh = MeshData {
            positions: m.positions,
            triangles: m.triangles,
        };
        let config = Config::new().with_ratio(spec.base_ratio);
        let (mut stream, _, _) =
            crate::pm::encode_mesh(&mesh, &config, spec.quantised, spec.chunk)?;
        let u32_at = |b: &[u8], o: usize| u32::from_le_bytes([b[o], b[o + 1], b[o + 2], b[o + 3]]);
        let (vertices, triangles) = (u32_at(&stream, 8) as usize, u32_at(&stream, 20) as usize);
        if let Some(f) = spec.truncate {
            if !(0.0..1.0).contains(&f) {
                bail!("stream case {}: truncate {f} must be in [0, 1)", spec.name);
            }
            stream.truncate((stream.len() as f64 * f as f64) as usize);
        }
        if let Some(k) = spec.flip_bit {
            let k = k % (8 * stream.len() as u64);
            stream[(k / 8) as usize] ^= 1 << (k % 8);
        }
        Ok(StreamCase {
            spec: spec.clone(),
            stream,
            vertices,
            triangles,
        })
    }

    /// The case's name.
    pub fn name(&self) -> &str {
        &self.spec.name
    }

    /// Whether a board with storage for `vertices` vertices, `triangles` triangles and a chunk
    /// buffer of `buffer` bytes holds the whole stream.
    pub fn fits(&self, vertices: usize, triangles: usize, buffer: usize) -> bool {
        self.vertices <= vertices
            && self.triangles <= triangles
            && usize::from(self.spec.chunk) + tinydecimate::stream::CHUNK_OVERHEAD <= buffer
    }
}

/// Every `[[stream]]` of `dir/cases.toml`, encoded.
pub fn load(dir: &Path) -> Result<Vec<StreamCase>> {
    golden::case::load_stream_specs(dir)?
        .iter()
        .map(StreamCase::from_spec)
        .collect()
}

/// The host's run of the case: the output file `meshfmt::pm::run` writes.
pub fn reference(case: &StreamCase) -> Vec<u8> {
    pm::run_in_memory(&case.stream, HOST_VERTICES, HOST_TRIANGLES, HOST_BUFFER)
}

const TAGS: [(u32, &str); 7] = [
    (Tag::Arrived as u32, "arrived"),
    (Tag::Final as u32, "final"),
    (Tag::Base as u32, "base"),
    (Tag::Refined as u32, "refined"),
    (Tag::Coarsened as u32, "coarsened"),
    (Tag::Full as u32, "full"),
    (Tag::Positions as u32, "positions"),
];

/// The golden files of an output of `case`.
pub fn golden_from_output(case: &StreamCase, backend: Backend, out: &[u8]) -> Result<Golden> {
    let Some((records, s)) = pm::parse(out) else {
        bail!("stream case {}: malformed output", case.name());
    };
    let bin = pm::compared(out);
    let spec = &case.spec;
    let mut t = String::new();
    let w = &mut t;
    writeln!(
        w,
        "# Golden result of stream case {:?} with the {backend} backend: written by\n\
         # `host-sim golden --bless`, checked by `host-sim golden --check` (host) and\n\
         # `host-sim qemu --check` (every board). {}.bin is the output of meshfmt::pm::run\n\
         # (records, then the trailer with its measurement block zeroed).",
        spec.name, spec.name
    )?;
    writeln!(w, "case = {:?}", spec.name)?;
    writeln!(w, "backend = \"{backend}\"")?;
    writeln!(w, "mesh = {:?}", spec.mesh)?;
    writeln!(
        w,
        "encoding = \"base ratio {}, {}, chunks of {} B\"",
        spec.base_ratio,
        if spec.quantised {
            "16-bit positions"
        } else {
            "f32 positions"
        },
        spec.chunk
    )?;
    if let Some(f) = spec.truncate {
        writeln!(w, "truncate = {f}")?;
    }
    if let Some(k) = spec.flip_bit {
        writeln!(w, "flip_bit = {k}")?;
    }
    writeln!(w, "stream_bytes = {}", case.stream.len())?;
    writeln!(w, "stream_sha256 = \"{}\"", sha256_hex(&case.stream))?;
    writeln!(w)?;
    match s.error {
        None => writeln!(w, "status = \"complete\"")?,
        Some(e) => writeln!(
            w,
            "status = \"stream error\"\nerror = {{ code = {}, a = {}, b = {} }}",
            e.code, e.a, e.b
        )?,
    }
    writeln!(w, "bytes_taken = {}", s.bytes)?;
    writeln!(w, "base_triangles = {}", s.base_triangles)?;
    writeln!(w, "triangles = {}", s.triangles)?;
    writeln!(w, "vertex_splits = {}", s.splits)?;
    writeln!(w, "vertices = {}", s.vertices)?;
    writeln!(w, "records = [")?;
    for r in &records {
        let tag = TAGS.iter().find(|t| t.0 == r.tag).map_or("?", |t| t.1);
        writeln!(
            w,
            "  {{ tag = {tag:?}, bytes = {}, triangles = {}, vertices = {} }},",
            r.bytes,
            r.triangles.len(),
            r.vertices
        )?;
    }
    writeln!(w, "]")?;
    writeln!(w, "bin_bytes = {}", bin.len())?;
    writeln!(w, "bin_sha256 = \"{}\"", sha256_hex(&bin))?;
    Ok(Golden { txt: t, bin })
}

/// Compares an output of `case` (host or board) with its golden files. A board that reports
/// a capacity error the host did not see cannot hold the stream: skipped.
pub fn judge(case: &StreamCase, backend: Backend, expected: &Golden, out: &[u8]) -> Verdict {
    let Some((_, s)) = pm::parse(out) else {
        return Verdict::Failed("malformed output file".into());
    };
    if s.error.is_some_and(|e| e.code == 4) {
        let host = pm::parse(&reference(case)).map(|(_, h)| h);
        if host.is_some_and(|h| h.error.is_none_or(|e| e.code != 4)) {
            let e = s.error.unwrap_or_default();
            return Verdict::Skipped(format!(
                "too big for this board: the stream needs {} where the board has {} ({} vertices, {} triangles)",
                e.a, e.b, case.vertices, case.triangles
            ));
        }
    }
    let got = match golden_from_output(case, backend, out) {
        Ok(g) => g,
        Err(e) => return Verdict::Failed(format!("{e:#}")),
    };
    diff(expected, &got)
}

/// The first differing byte of the output and the differing lines of the text.
pub fn diff(expected: &Golden, got: &Golden) -> Verdict {
    let mut d = Vec::new();
    if expected.bin != got.bin {
        let at = expected
            .bin
            .iter()
            .zip(&got.bin)
            .position(|(a, b)| a != b)
            .unwrap_or(expected.bin.len().min(got.bin.len()));
        d.push(format!(
            "first differing byte of the output: {at} ({} vs {} bytes)",
            expected.bin.len(),
            got.bin.len()
        ));
    }
    golden::text_diff(&expected.txt, &got.txt, &mut d);
    if d.is_empty() {
        Verdict::Identical
    } else {
        Verdict::Diff(d)
    }
}

/// The records and trailer of an output (for printing).
pub fn parse(out: &[u8]) -> Option<(Vec<Record>, Summary)> {
    pm::parse(out)
}

/// Checks every stream case on the host against `dir/<backend>/`.
pub fn check_host(dir: &Path, backend: Backend) -> Result<Vec<(StreamCase, Verdict)>> {
    let mut out = Vec::new();
    for case in load(dir)? {
        let now = reference(&case);
        let v = match Golden::load(dir, backend, case.name())? {
            Some(g) => judge(&case, backend, &g, &now),
            None => Verdict::Failed(format!(
                "no golden files {}/{backend}/{}.txt|.bin (run `host-sim golden --bless --backend {backend}`)",
                dir.display(),
                case.name()
            )),
        };
        out.push((case, v));
    }
    Ok(out)
}

/// Rewrites the stream goldens; one line per case.
pub fn bless(dir: &Path, backend: Backend) -> Result<Vec<String>> {
    let mut lines = Vec::new();
    for case in load(dir)? {
        let new = golden_from_output(&case, backend, &reference(&case))?;
        let sha = &sha256_hex(&new.bin)[..16];
        let line = match Golden::load(dir, backend, case.name())? {
            None => format!("{:<28} new      sha256 {sha}", case.name()),
            Some(old) if old == new => format!("{:<28} same     sha256 {sha}", case.name()),
            Some(old) => {
                let mut s = format!("{:<28} CHANGED  sha256 {sha}", case.name());
                if let Verdict::Diff(d) = diff(&old, &new) {
                    for l in d {
                        let _ = write!(s, "\n{:<37}{l}", "");
                    }
                }
                s
            }
        };
        new.save(dir, backend, case.name())?;
        lines.push(line);
    }
    Ok(lines)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stream_goldens_pass_on_the_host() {
        let bad: Vec<_> = check_host(&golden::default_dir(), Backend::compiled())
            .unwrap()
            .into_iter()
            .filter(|(_, v)| *v != Verdict::Identical)
            .map(|(c, v)| format!("{}: {v:?}", c.name()))
            .collect();
        assert!(bad.is_empty(), "{}", bad.join("\n"));
    }

    /// The cases cover what they promise: a complete stream with f32 and one with quantised
    /// positions, a cut one and a corrupted one (each ends in a typed error with a valid mesh
    /// that the slider still moves over), an open mesh, and a case that only the 4 MB boards
    /// hold.
    #[test]
    fn stream_cases_cover_the_decoder() {
        let cases = load(&golden::default_dir()).unwrap();
        let outs: Vec<_> = cases
            .iter()
            .map(|c| pm::parse(&reference(c)).unwrap())
            .collect();
        let has = |f: &dyn Fn(&StreamCase, &Summary) -> bool| {
            cases.iter().zip(&outs).any(|(c, (_, s))| f(c, s))
        };
        assert!(has(&|c, s| s.error.is_none() && !c.spec.quantised));
        assert!(has(&|c, s| s.error.is_none() && c.spec.quantised));
        assert!(has(&|c, s| c.spec.truncate.is_some()
            && s.error.is_some_and(|e| e.code == 9)
            && s.splits > 0));
        assert!(has(&|c, s| c.spec.flip_bit.is_some()
            && s.error.is_some_and(|e| e.code == 3)
            && s.splits > 0));
        assert!(has(&|c, _| !c.fits(100, 1_190, 272)));
        assert!(cases.iter().filter(|c| c.fits(44, 212, 80)).count() >= 3);
        // Every output: the slider comes back to the final mesh exactly; the final mesh of a
        // complete stream is the input's (as the encoder numbered it).
        for (c, (records, s)) in cases.iter().zip(&outs) {
            let get = |t: Tag| records.iter().find(|r| r.tag == t as u32).unwrap();
            assert_eq!(
                get(Tag::Final).triangles,
                get(Tag::Full).triangles,
                "{}",
                c.name()
            );
            assert_eq!(
                get(Tag::Base).triangles.len(),
                s.base_triangles as usize,
                "{}",
                c.name()
            );
            if s.error.is_none() {
                assert_eq!(s.triangles as usize, c.triangles, "{}", c.name());
            } else {
                assert!((s.triangles as usize) < c.triangles, "{}", c.name());
            }
        }
    }
}
