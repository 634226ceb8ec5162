//! A checksum sealed onto every result file this crate writes, checked
//! before a file is handed back to the HDF5 reader (`--resume`, `merge`,
//! `plot`): a damaged file is refused by name, before its bytes are
//! parsed, instead of being read as whatever the damage made of it (the
//! HDF5 C library, used before hdf5-pure, read out of bounds or asked for
//! impossible allocations on such files).
//!
//! The seal is 24 bytes appended after the HDF5 data: the magic
//! `cosserat-seal-v1` and the FNV-1a 64-bit hash of every byte before it
//! (Fowler, Noll, Vo). HDF5 ignores bytes past the end of its data (the
//! end-of-allocation address in the superblock), so h5py, MATLAB and
//! ParaView read sealed files as before. A file without a seal (written by
//! another program, or an older cosserat) is read unverified.

use std::io::{Read, Seek, SeekFrom, Write};
use std::path::Path;

const MAGIC: &[u8; 16] = b"cosserat-seal-v1";
const TRAILER: u64 = 24;

/// What the seal says about a file.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Seal {
    /// The seal is present and the bytes match it.
    Verified,
    /// No seal: the file was not written by this version of cosserat.
    Absent,
}

/// FNV-1a over a stream of `len` bytes.
fn hash(reader: &mut impl Read, mut len: u64) -> std::io::Result<u64> {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    let mut buf = vec![0u8; 1 << 16];
    while len > 0 {
        let n = (len.min(buf.len() as u64)) as usize;
        reader.read_exact(&mut buf[..n])?;
        for &b in &buf[..n] {
            h ^= u64::from(b);
            h = h.wrapping_mul(0x0000_0100_0000_01b3);
        }
        len -= n as u64;
    }
    Ok(h)
}

/// Appends the seal to a finished file.
pub fn seal(path: &Path) -> std::io::Result<()> {
    let len = std::fs::metadata(path)?.len();
    let h = hash(
        &mut std::io::BufReader::new(std::fs::File::open(path)?),
        len,
    )?;
    let mut f = std::fs::OpenOptions::new().append(true).open(path)?;
    f.write_all(MAGIC)?;
    f.write_all(&h.to_le_bytes())?;
    f.sync_all()
}

/// Checks a file's seal: Err names the damage.
pub fn check(path: &Path) -> Result<Seal, String> {
    let fail = |e: std::io::Error| format!("cannot read {}: {e}", path.display());
    let mut f = std::fs::File::open(path).map_err(fail)?;
    let meta = f.metadata().map_err(fail)?;
    if !meta.is_file() {
        return Err(format!("{} is not a regular file", path.display()));
    }
    let len = meta.len();
    if len < TRAILER {
        return Ok(Seal::Absent);
    }
    let mut tail = [0u8; 24];
    f.seek(SeekFrom::Start(len - TRAILER)).map_err(fail)?;
    f.read_exact(&mut tail).map_err(fail)?;
    // A seal whose magic is itself damaged is still a seal: 12 of its 16
    // bytes in place cannot happen by chance in an unsealed file.
    let alike = tail[..16].iter().zip(MAGIC).filter(|(a, b)| a == b).count();
    if alike < 12 {
        return Ok(Seal::Absent);
    }
    f.seek(SeekFrom::Start(0)).map_err(fail)?;
    let h = hash(&mut std::io::BufReader::new(f), len - TRAILER).map_err(fail)?;
    let sealed = u64::from_le_bytes(tail[16..].try_into().expect("8 bytes"));
    if h == sealed {
        Ok(Seal::Verified)
    } else {
        Err(format!(
            "{} is damaged: its bytes do not match the checksum cosserat sealed it with",
            path.display()
        ))
    }
}

/// Reads a result file whole after checking its seal.
#[cfg(feature = "hdf5")]
pub fn open(path: &Path) -> Result<super::store::Group, super::store::StoreError> {
    check(path).map_err(super::store::StoreError::Unreadable)?;
    super::store::read(path)
}
