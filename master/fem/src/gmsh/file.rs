//! Reading a mesh file from disk: only a regular file, and only up to
//! [`MAX_MESH_FILE_BYTES`](super::MAX_MESH_FILE_BYTES), so that `/dev/zero`, a FIFO or a
//! directory named as the mesh is refused by name instead of being read until memory runs out
//! (or forever).

use super::{GmshError, Result};
use std::fs::{File, Metadata};
use std::io::Read;
use std::path::Path;

/// What a file that is not a regular one is (`a directory`, `a character device`, ...), for
/// messages that refuse it.
fn file_kind(meta: &Metadata) -> &'static str {
    let t = meta.file_type();
    if t.is_dir() {
        return "a directory";
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if t.is_char_device() {
            return "a character device";
        }
        if t.is_block_device() {
            return "a block device";
        }
        if t.is_fifo() {
            return "a FIFO (named pipe)";
        }
        if t.is_socket() {
            return "a socket";
        }
    }
    "not a regular file"
}

/// The bytes of the regular file `path`, at most `limit` of them (the mesh reader's and the
/// job file's): anything else is [`GmshError::NotAFile`] or [`GmshError::TooLarge`].
pub fn read_regular(path: &Path, limit: u64) -> Result<Vec<u8>> {
    let io = |source| GmshError::Io { path: path.to_path_buf(), source };
    let not_a_file =
        |meta: &Metadata| GmshError::NotAFile { path: path.to_path_buf(), kind: file_kind(meta) };
    let too_large = |size: u64| GmshError::TooLarge { path: path.to_path_buf(), size, limit };
    // Checked before opening: opening a FIFO blocks until a writer comes.
    let meta = std::fs::metadata(path).map_err(io)?;
    if !meta.is_file() {
        return Err(not_a_file(&meta));
    }
    if meta.len() > limit {
        return Err(too_large(meta.len()));
    }
    let file = File::open(path).map_err(io)?;
    // Again on what was opened (the path may have changed in between).
    let meta = file.metadata().map_err(io)?;
    if !meta.is_file() {
        return Err(not_a_file(&meta));
    }
    let mut bytes = Vec::with_capacity(meta.len().min(limit) as usize);
    file.take(limit + 1).read_to_end(&mut bytes).map_err(io)?;
    if bytes.len() as u64 > limit {
        return Err(too_large(bytes.len() as u64));
    }
    Ok(bytes)
}

#[cfg(test)]
mod tests {
    use super::super::{GmshError, MAX_MESH_FILE_BYTES, read_msh};
    use std::path::PathBuf;

    /// A fresh directory for one test.
    fn scratch(name: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("cosdem-gmsh-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        dir
    }

    /// `/dev/zero` was read until memory ran out, a FIFO blocked forever: a device, a FIFO and a
    /// directory are refused naming the path and what it is, before anything is read.
    #[cfg(unix)]
    #[test]
    fn a_device_a_fifo_or_a_directory_is_refused_naming_it() {
        let dir = scratch("kinds");
        let fifo = dir.join("mesh.msh");
        let made = std::process::Command::new("mkfifo").arg(&fifo).status();
        let mut cases =
            vec![(PathBuf::from("/dev/zero"), "a character device"), (dir.clone(), "a directory")];
        if made.is_ok_and(|s| s.success()) {
            cases.push((fifo, "a FIFO"));
        }
        for (path, kind) in cases {
            let err = read_msh(&path).unwrap_err();
            assert!(matches!(err, GmshError::NotAFile { .. }), "{}: {err}", path.display());
            let msg = err.to_string();
            assert!(msg.contains(&path.display().to_string()) && msg.contains(kind), "{msg}");
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// A file larger than any mesh the solver takes is refused before it is read, with its size
    /// and the limit (a sparse file: nothing is written to disk).
    #[test]
    fn a_file_over_the_limit_is_refused_with_the_limit() {
        let dir = scratch("size");
        let path = dir.join("huge.msh");
        std::fs::File::create(&path).unwrap().set_len(MAX_MESH_FILE_BYTES + 1).unwrap();
        let err = read_msh(&path).unwrap_err();
        assert!(
            matches!(err, GmshError::TooLarge { size, limit, .. }
                if size == MAX_MESH_FILE_BYTES + 1 && limit == MAX_MESH_FILE_BYTES),
            "{err}"
        );
        let msg = err.to_string();
        assert!(msg.contains("huge.msh") && msg.contains("MAX_MESH_FILE_BYTES"), "{msg}");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
