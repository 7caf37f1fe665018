//! The firmware's log: defmt frames decoded with the image's own table.

use anyhow::{anyhow, Result};

/// Decodes defmt frames (rzCOBS, as defmt-semihosting sends them) with the image's table.
pub fn decode_defmt(elf: &[u8], stream: &[u8]) -> Result<Vec<String>> {
    use defmt_decoder::{DecodeError, Table};
    let table = Table::parse(elf)?.ok_or_else(|| anyhow!("the image has no .defmt table"))?;
    let locations = table.get_locations(elf).unwrap_or_default();
    let mut decoder = table.new_stream_decoder();
    decoder.received(stream);
    let mut lines = Vec::new();
    loop {
        match decoder.decode() {
            Ok(frame) => {
                let loc = locations
                    .get(&frame.index())
                    .map(|l| {
                        let file = l.file.file_name().unwrap_or_default().to_string_lossy();
                        format!("  ({file}:{})", l.line)
                    })
                    .unwrap_or_default();
                lines.push(format!("{}{loc}", frame.display(false)));
            }
            Err(DecodeError::UnexpectedEof) => break,
            Err(DecodeError::Malformed) => {
                lines.push("<malformed defmt frame>".into());
                if !table.encoding().can_recover() {
                    break;
                }
            }
        }
    }
    Ok(lines)
}
