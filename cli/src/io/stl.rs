//! STL in (ascii and binary, via `stl_io`, corners welded by exact position) and binary STL
//! out (see [`crate::io`]).

use std::collections::HashMap;
use std::io::Cursor;

use super::MeshData;

/// Binary STL: an 80-byte header, the count, and per triangle its unit normal (zero if it has
/// no area), three corners and a zero attribute word. STL has no vertex numbering: reading it
/// back welds corners by position.
pub(crate) fn stl_bytes(mesh: &MeshData) -> std::result::Result<Vec<u8>, String> {
    let n = u32::try_from(mesh.triangles.len()).map_err(|_| "too many triangles for STL")?;
    let mut b = Vec::with_capacity(84 + 50 * mesh.triangles.len());
    let mut header = [b' '; 80];
    let text = b"binary STL written by tinydecimate host-sim";
    header[..text.len()].copy_from_slice(text);
    b.extend_from_slice(&header);
    b.extend_from_slice(&n.to_le_bytes());
    for t in &mesh.triangles {
        let mut p = [[0f32; 3]; 3];
        for (slot, &i) in p.iter_mut().zip(t) {
            *slot = *mesh
                .positions
                .get(i as usize)
                .ok_or_else(|| format!("a triangle refers to vertex {i}, past the last"))?;
        }
        let e1 = [0, 1, 2].map(|k| f64::from(p[1][k]) - f64::from(p[0][k]));
        let e2 = [0, 1, 2].map(|k| f64::from(p[2][k]) - f64::from(p[0][k]));
        let cr = [
            e1[1] * e2[2] - e1[2] * e2[1],
            e1[2] * e2[0] - e1[0] * e2[2],
            e1[0] * e2[1] - e1[1] * e2[0],
        ];
        let len = (cr[0] * cr[0] + cr[1] * cr[1] + cr[2] * cr[2]).sqrt();
        let nrm = if len > 0.0 && len.is_finite() {
            cr.map(|x| (x / len) as f32)
        } else {
            [0.0; 3]
        };
        for v in [nrm, p[0], p[1], p[2]] {
            for x in v {
                b.extend_from_slice(&x.to_le_bytes());
            }
        }
        b.extend_from_slice(&[0, 0]);
    }
    Ok(b)
}

/// Whether `bytes` is a binary STL by its size: `84 + 50 n` with `n` at offset 80.
pub(crate) fn stl_size_matches_binary(bytes: &[u8]) -> bool {
    bytes
        .get(80..84)
        .map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]]) as usize)
        .and_then(|n| n.checked_mul(50))
        .and_then(|s| s.checked_add(84))
        == Some(bytes.len())
}

pub(crate) fn parse_stl(bytes: &[u8]) -> std::result::Result<MeshData, String> {
    // Ascii: starts with "solid" and its first KiB is plain ASCII text (a binary file, even with
    // a "solid" header, has NUL or high bytes in its triangle count or floats).
    let head = &bytes[..bytes.len().min(1024)];
    let looks_ascii = bytes.trim_ascii_start().starts_with(b"solid")
        && head.iter().all(|&b| b != 0 && b.is_ascii());
    let binary = stl_size_matches_binary(bytes) || !looks_ascii;
    if binary {
        if bytes.len() < 84 {
            return Err(format!(
                "binary STL truncated: {} bytes, the header alone takes 84",
                bytes.len()
            ));
        }
        if !stl_size_matches_binary(bytes) {
            let n = u32::from_le_bytes([bytes[80], bytes[81], bytes[82], bytes[83]]) as u64;
            let complete = (bytes.len() as u64 - 84) / 50;
            return Err(format!(
                "binary STL: header says {n} triangles ({} bytes) but the file has {} bytes; \
                 triangle {} at byte offset {} is {}",
                84 + 50 * n,
                bytes.len(),
                complete + 1,
                84 + 50 * complete,
                if complete < n {
                    "incomplete (truncated file?)"
                } else {
                    "followed by extra bytes"
                }
            ));
        }
    }
    // stl_io probes ascii by a first line starting with "solid "; a binary header may too, so
    // hand it a copy whose (ignored) header is blanked.
    let mut data = bytes.to_vec();
    if binary {
        data[..80].fill(0);
    }
    let mut cursor = Cursor::new(data);
    let iter = stl_io::create_stl_reader(&mut cursor).map_err(|e| format!("STL: {e}"))?;
    let mut mesh = MeshData::default();
    let mut welded: HashMap<[u32; 3], u32> = HashMap::new();
    for (k, t) in iter.enumerate() {
        let t = t.map_err(|e| {
            if binary {
                format!(
                    "binary STL triangle {} at byte offset {}: {e}",
                    k + 1,
                    84 + 50 * k
                )
            } else {
                let line = ascii_facet_line(bytes, k)
                    .map(|l| format!(" (from line {l})"))
                    .unwrap_or_default();
                format!("ascii STL facet {}{line}: {e}", k + 1)
            }
        })?;
        let mut tri = [0u32; 3];
        for (slot, v) in tri.iter_mut().zip(t.vertices.iter()) {
            let key = v.0.map(f32::to_bits);
            let next = u32::try_from(mesh.positions.len()).map_err(|_| "too many vertices")?;
            *slot = *welded.entry(key).or_insert_with(|| {
                mesh.positions.push(v.0);
                next
            });
        }
        mesh.triangles.push(tri);
    }
    Ok(mesh)
}

/// 1-based line on which the `k`-th (0-based) `facet` of an ascii STL starts, or the last
/// line if there are fewer facets.
pub(crate) fn ascii_facet_line(bytes: &[u8], k: usize) -> Option<usize> {
    let text = String::from_utf8_lossy(bytes);
    let mut seen = 0;
    let mut last = 0;
    for (no, line) in text.lines().enumerate() {
        last = no + 1;
        if line.split_whitespace().next() == Some("facet") {
            if seen == k {
                return Some(no + 1);
            }
            seen += 1;
        }
    }
    (last > 0).then_some(last)
}
