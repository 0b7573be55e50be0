//! Reads refuse what is not a regular file or is too large; writes follow
//! symbolic links, write FIFOs through, never touch an unrelated file and
//! leave every target as it was when one output fails.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test may panic

use std::io::Read;
use std::path::{Path, PathBuf};

use trilux_files::{FileIdentity, Output, ReadError, read_limited, write_all, write_one};

fn folder(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("files-{name}"));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn mkfifo(path: &Path) {
    let status = std::process::Command::new("mkfifo")
        .arg(path)
        .status()
        .unwrap();
    assert!(status.success());
}

fn names(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

#[test]
fn reads_refuse_fifos_folders_and_large_files() {
    let dir = folder("read");
    let fifo = dir.join("pipe");
    mkfifo(&fifo);
    // Never opened, so never blocks.
    let e = read_limited(&fifo, 100).unwrap_err();
    assert!(matches!(e, ReadError::NotRegular { kind: "a FIFO" }), "{e}");
    let e = read_limited(&dir, 100).unwrap_err();
    assert_eq!(e.to_string(), "it is a folder, not a regular file");
    let big = dir.join("big");
    std::fs::write(&big, vec![b'x'; 101]).unwrap();
    let e = read_limited(&big, 100).unwrap_err();
    assert!(
        matches!(
            e,
            ReadError::TooLarge {
                size: 101,
                limit: 100
            }
        ),
        "{e}"
    );
    assert_eq!(read_limited(&big, 101).unwrap().len(), 101);
    // A symbolic link to a FIFO is refused as the FIFO.
    let link = dir.join("link");
    std::os::unix::fs::symlink(&fifo, &link).unwrap();
    assert!(matches!(
        read_limited(&link, 100),
        Err(ReadError::NotRegular { .. })
    ));
}

#[test]
fn a_symbolic_link_stays_a_link_and_its_target_is_replaced() {
    let dir = folder("symlink");
    let real = dir.join("real.txt");
    std::fs::write(&real, "old").unwrap();
    let link = dir.join("link.txt");
    std::os::unix::fs::symlink("real.txt", &link).unwrap();
    write_one(&link, "test output", b"new").unwrap();
    assert!(
        std::fs::symlink_metadata(&link)
            .unwrap()
            .file_type()
            .is_symlink()
    );
    assert_eq!(std::fs::read_to_string(&real).unwrap(), "new");
    // A dangling link makes the file it names.
    let dangling = dir.join("dangling.txt");
    std::os::unix::fs::symlink("made.txt", &dangling).unwrap();
    write_one(&dangling, "test output", b"made").unwrap();
    assert!(
        std::fs::symlink_metadata(&dangling)
            .unwrap()
            .file_type()
            .is_symlink()
    );
    assert_eq!(
        std::fs::read_to_string(dir.join("made.txt")).unwrap(),
        "made"
    );
    assert_eq!(
        names(&dir),
        ["dangling.txt", "link.txt", "made.txt", "real.txt"]
    );
}

#[test]
fn a_fifo_is_written_through() {
    let dir = folder("fifo");
    let fifo = dir.join("pipe");
    mkfifo(&fifo);
    let reader = {
        let fifo = fifo.clone();
        std::thread::spawn(move || {
            let mut s = String::new();
            std::fs::File::open(&fifo)
                .unwrap()
                .read_to_string(&mut s)
                .unwrap();
            s
        })
    };
    let out = Output::plan(&fifo, "test output").unwrap();
    assert!(out.is_write_through());
    write_all(&[(&out, b"through")]).unwrap();
    assert_eq!(reader.join().unwrap(), "through");
    let meta = std::fs::symlink_metadata(&fifo).unwrap();
    assert!(std::os::unix::fs::FileTypeExt::is_fifo(&meta.file_type()));
}

#[test]
fn temporary_names_never_collide_with_existing_files() {
    let dir = folder("collide");
    let target = dir.join("keep.sol");
    // Every name the old scheme or an obvious one would pick.
    for name in ["keep.tmp-trilux", ".keep.sol.tmp", "keep.sol.tmp"] {
        std::fs::write(dir.join(name), "unrelated").unwrap();
    }
    let pid = std::process::id();
    for k in 0..3 {
        std::fs::write(
            dir.join(format!(".keep.sol.trilux-{pid}-{k}.tmp")),
            "unrelated",
        )
        .unwrap();
    }
    write_one(&target, "solution", b"solution").unwrap();
    assert_eq!(std::fs::read_to_string(&target).unwrap(), "solution");
    for name in names(&dir).iter().filter(|n| *n != "keep.sol") {
        assert_eq!(
            std::fs::read_to_string(dir.join(name)).unwrap(),
            "unrelated",
            "{name}"
        );
    }
    assert_eq!(names(&dir).len(), 7);
}

#[test]
fn all_or_none() {
    let dir = folder("all-or-none");
    let a = dir.join("a.txt");
    std::fs::write(&a, "old a").unwrap();
    let b_dir = dir.join("sub");
    std::fs::create_dir(&b_dir).unwrap();
    let b = b_dir.join("b.txt");
    let (oa, ob) = (
        Output::plan(&a, "first").unwrap(),
        Output::plan(&b, "second").unwrap(),
    );
    // The second output's folder disappears after planning: nothing is
    // written, not even the first.
    std::fs::remove_dir(&b_dir).unwrap();
    let e = write_all(&[(&oa, b"new a"), (&ob, b"new b")]).unwrap_err();
    assert!(
        e.to_string().contains("b.txt: cannot write the second"),
        "{e}"
    );
    assert_eq!(std::fs::read_to_string(&a).unwrap(), "old a");
    assert_eq!(names(&dir), ["a.txt"]);
}

#[test]
fn planning_refuses_folders_and_missing_folders() {
    let dir = folder("plan");
    let e = Output::plan(&dir, "image").unwrap_err();
    assert!(
        e.to_string()
            .ends_with("cannot write the image: it is a folder"),
        "{e}"
    );
    let e = Output::plan(&dir.join("no/x.exr"), "image").unwrap_err();
    assert!(e.to_string().contains("the folder"), "{e}");
    assert!(e.to_string().ends_with("does not exist"), "{e}");
    assert!(names(&dir).is_empty());
}

#[test]
fn identities_see_through_links_and_dot_dot() {
    let dir = folder("identity");
    std::fs::create_dir(dir.join("sub")).unwrap();
    let f = dir.join("f.xml");
    std::fs::write(&f, "x").unwrap();
    let id = |p: &Path| FileIdentity::of(p).unwrap();
    assert_eq!(id(&f), id(&dir.join("sub/../f.xml")));
    std::fs::hard_link(&f, dir.join("hard.xml")).unwrap();
    assert_eq!(id(&f), id(&dir.join("hard.xml")));
    std::os::unix::fs::symlink(&f, dir.join("soft.xml")).unwrap();
    assert_eq!(id(&f), id(&dir.join("soft.xml")));
    // Files still to be made compare by folder and name.
    assert_eq!(id(&dir.join("new.sol")), id(&dir.join("sub/../new.sol")));
    assert_ne!(id(&dir.join("new.sol")), id(&dir.join("other.sol")));
    std::os::unix::fs::symlink("new.sol", dir.join("to-new.sol")).unwrap();
    assert_eq!(id(&dir.join("new.sol")), id(&dir.join("to-new.sol")));
}
