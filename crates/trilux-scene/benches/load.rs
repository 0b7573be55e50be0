//! Loading speed: the bundled scenes (XML parse, resolve, build).
//!
//! `cargo bench -p trilux-scene --bench load -- --warm-up-time 1 --measurement-time 3`
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test, bench or example may panic

use std::path::PathBuf;

use criterion::{Criterion, criterion_group, criterion_main};

fn scenes() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../scenes")
}

fn load(c: &mut Criterion) {
    for name in ["cornell-box.xml", "furnace.xml"] {
        let path = scenes().join(name);
        let text = std::fs::read_to_string(&path).expect("bundled scene");
        c.bench_function(&format!("load {name}"), |b| {
            b.iter(|| trilux_scene::load_str(&text, &path).expect("loads"))
        });
    }
}

criterion_group!(benches, load);
criterion_main!(benches);
