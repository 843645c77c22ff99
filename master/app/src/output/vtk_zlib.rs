//! Compressed binary arrays of `.vtu` files (`[output] vtk_format = "binary"`), in VTK's
//! `vtkZLibDataCompressor` layout with a `UInt64` header, inline:
//!
//! ```text
//! base64(header) base64(block_0 block_1 ...)
//! header = [number of blocks, block size, size of the last block, compressed size of each block]
//! ```
//!
//! The raw data (the array's little-endian values) is cut into blocks of [`BLOCK_SIZE`] bytes
//! (the last one shorter), each zlib-compressed; the header and the data are base64-encoded
//! separately, as VTK's own writer does for inline data. Compression is deterministic: the
//! same array gives the same bytes.

use flate2::Compression;
use flate2::read::ZlibDecoder;
use flate2::write::ZlibEncoder;
use std::io::{Read as _, Write as _};

/// The `compressor` attribute of the `<VTKFile>` element.
pub const COMPRESSOR: &str = "vtkZLibDataCompressor";

/// Uncompressed bytes per block (VTK's default).
pub const BLOCK_SIZE: usize = 32 * 1024;

/// Appends the compressed, base64-encoded form of `raw` to `s`.
pub(crate) fn push_compressed(s: &mut String, raw: &[u8]) {
    let blocks: Vec<Vec<u8>> = raw
        .chunks(BLOCK_SIZE)
        .map(|chunk| {
            let mut z = ZlibEncoder::new(Vec::new(), Compression::default());
            z.write_all(chunk).expect("writing into a Vec cannot fail");
            z.finish().expect("writing into a Vec cannot fail")
        })
        .collect();
    let last = match raw.len() % BLOCK_SIZE {
        0 if raw.is_empty() => 0,
        0 => BLOCK_SIZE,
        r => r,
    };
    let mut header: Vec<u64> = vec![blocks.len() as u64, BLOCK_SIZE as u64, last as u64];
    header.extend(blocks.iter().map(|b| b.len() as u64));
    let header: Vec<u8> = header.iter().flat_map(|v| v.to_le_bytes()).collect();
    super::vtk::push_base64(s, &header);
    super::vtk::push_base64(s, &blocks.concat());
}

/// The raw bytes of an array written by [`push_compressed`] (whitespace ignored).
pub(crate) fn decode_compressed(text: &str) -> Result<Vec<u8>, String> {
    let clean: String = text.chars().filter(|c| !c.is_ascii_whitespace()).collect();
    // 24 bytes (three UInt64) are exactly 32 base64 characters: the block count comes first.
    let first = clean.get(..32).ok_or("compressed array shorter than its header")?;
    let first = super::vtu_read::base64(first)?;
    let n = u64::from_le_bytes(first[..8].try_into().expect("8 bytes")) as usize;
    let header_bytes = n.checked_add(3).and_then(|k| k.checked_mul(8)).ok_or("bad block count")?;
    let header_chars = header_bytes.div_ceil(3) * 4;
    let header =
        clean.get(..header_chars).ok_or_else(|| format!("header of {n} blocks cut short"))?;
    let header = super::vtu_read::base64(header)?;
    let word = |i: usize| u64::from_le_bytes(header[8 * i..8 * i + 8].try_into().expect("8 bytes"));
    let (block, last) = (word(1) as usize, word(2) as usize);
    let data = super::vtu_read::base64(&clean[header_chars..])?;
    let mut raw = Vec::with_capacity(n.saturating_mul(block));
    let mut at = 0usize;
    for i in 0..n {
        let size = word(3 + i) as usize;
        let end = at.checked_add(size).filter(|&e| e <= data.len());
        let end = end.ok_or_else(|| format!("block {i} of {size} bytes runs past the data"))?;
        let before = raw.len();
        ZlibDecoder::new(&data[at..end])
            .read_to_end(&mut raw)
            .map_err(|e| format!("block {i}: {e}"))?;
        let want = if i + 1 == n { last } else { block };
        if raw.len() - before != want {
            return Err(format!("block {i} inflates to {} bytes, not {want}", raw.len() - before));
        }
        at = end;
    }
    Ok(raw)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Arrays of 0 bytes, less than a block, exactly one block and several blocks with a
    /// short last one come back byte for byte; a corrupted block is an error naming it.
    #[test]
    fn compressed_arrays_round_trip() {
        for len in [0, 17, BLOCK_SIZE, 2 * BLOCK_SIZE + 123] {
            let raw: Vec<u8> = (0..len).map(|i| (i * 7 % 251) as u8).collect();
            let mut s = String::new();
            push_compressed(&mut s, &raw);
            assert_eq!(decode_compressed(&s).unwrap(), raw, "{len} bytes");
        }
        let raw = vec![1u8; 1000];
        let mut s = String::new();
        push_compressed(&mut s, &raw);
        let mut bad = s.clone();
        bad.truncate(s.len() - 8);
        bad.push_str("AAAAAAAA");
        assert!(decode_compressed(&bad).unwrap_err().contains("block 0"));
    }
}
