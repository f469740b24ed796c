//! Writing output files whole or not at all: every file is first written to a temporary file in
//! the destination directory, and only when all of them are complete are they renamed into place.

use std::io::Write;
use std::path::{Path, PathBuf};

/// Write `files` (name, contents) into `dir` (created if missing). On any error nothing is
/// renamed into place and the temporary files are removed.
pub fn write_all_atomic(dir: &Path, files: &[(&str, &[u8])]) -> std::io::Result<Vec<PathBuf>> {
    std::fs::create_dir_all(dir)?;
    let mut temps = Vec::with_capacity(files.len());
    for (name, bytes) in files {
        let mut tmp = tempfile::Builder::new()
            .prefix(&format!(".{name}."))
            .suffix(".tmp")
            .tempfile_in(dir)?;
        tmp.write_all(bytes)?;
        tmp.as_file().sync_all()?;
        temps.push((tmp, dir.join(name)));
    }
    let mut out = Vec::with_capacity(temps.len());
    for (tmp, dest) in temps {
        tmp.persist(&dest).map_err(|e| e.error)?;
        out.push(dest);
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn writes_files_and_leaves_no_temporaries() {
        let d = tempfile::tempdir().unwrap();
        let sub = d.path().join("run");
        let paths = write_all_atomic(&sub, &[("a.txt", b"one"), ("b.txt", b"two")]).unwrap();
        assert_eq!(paths.len(), 2);
        assert_eq!(std::fs::read(sub.join("a.txt")).unwrap(), b"one");
        let names: Vec<_> = std::fs::read_dir(&sub)
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        assert_eq!(names.len(), 2, "{names:?}");
    }
}
