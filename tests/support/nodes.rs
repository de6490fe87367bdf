//! Special files made in a test's own temporary directory — never the machine's `/dev`: a
//! test that writes to `/dev/null` as root can replace the machine's `/dev/null` when the
//! program under test renames over its output (issue 38).

use std::path::{Path, PathBuf};
use std::process::Command;

/// Whether the tests run as root (needed to make a device node with `mknod`).
pub fn is_root() -> bool {
    Command::new("id")
        .arg("-u")
        .output()
        .is_ok_and(|o| String::from_utf8_lossy(&o.stdout).trim() == "0")
}

/// A character device `name` in `dir` with the numbers of `/dev/null` (1, 3) or `/dev/full`
/// (1, 7); `None` when not root (`mknod` refuses).
pub fn char_device(dir: &Path, name: &str, minor: u32) -> Option<PathBuf> {
    let p = dir.join(name);
    let _ = std::fs::remove_file(&p);
    let ok = Command::new("mknod")
        .arg(&p)
        .args(["c", "1", &minor.to_string()])
        .status()
        .is_ok_and(|s| s.success());
    ok.then_some(p)
}

/// Whether `p` is a character device.
pub fn is_char_device(p: &Path) -> bool {
    use std::os::unix::fs::FileTypeExt;
    std::fs::symlink_metadata(p).is_ok_and(|m| m.file_type().is_char_device())
}

/// A FIFO `name` in `dir` (made with `mkfifo`).
pub fn fifo(dir: &Path, name: &str) -> PathBuf {
    let p = dir.join(name);
    let _ = std::fs::remove_file(&p);
    let ok = Command::new("mkfifo")
        .arg(&p)
        .status()
        .is_ok_and(|s| s.success());
    assert!(ok, "mkfifo {}", p.display());
    p
}

/// A sink that discards what is written to it, in `dir`: a null device node when root, else a
/// FIFO with a reader thread that reads to the end (the thread waits in `open` until a writer
/// comes, and returns the number of bytes read).
pub fn discard_sink(dir: &Path) -> (PathBuf, Option<std::thread::JoinHandle<u64>>) {
    if let Some(p) = char_device(dir, "null", 3) {
        return (p, None);
    }
    let p = fifo(dir, "sink");
    let q = p.clone();
    let reader = std::thread::spawn(move || {
        let mut f = std::fs::File::open(&q).expect("the FIFO opens for reading");
        std::io::copy(&mut f, &mut std::io::sink()).unwrap_or(0)
    });
    (p, Some(reader))
}
