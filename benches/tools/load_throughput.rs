//! Load + write throughput over a list of MJCF files, best of N runs, as one JSON line.
//! Used by `benches/compare/bench_compare.sh` for the same-run comparison with robosuite.
//!
//! `cargo run --release --example load_throughput -- --runs 20 FILE...`

use std::time::Instant;

use mjcf_forge::Document;

fn main() {
    let mut args: Vec<String> = std::env::args().skip(1).collect();
    let mut runs = 20usize;
    if args.first().map(String::as_str) == Some("--runs") {
        runs = args[1].parse().expect("--runs N");
        args.drain(..2);
    }
    let bytes: u64 = args
        .iter()
        .map(|f| std::fs::metadata(f).expect(f).len())
        .sum();
    let mut best = f64::INFINITY;
    let mut out_chars = 0usize;
    for _ in 0..runs.max(1) {
        let start = Instant::now();
        out_chars = 0;
        for f in &args {
            let doc = Document::load(f).unwrap_or_else(|e| panic!("{e}"));
            out_chars += doc.to_xml_string().len();
        }
        best = best.min(start.elapsed().as_secs_f64());
    }
    println!(
        "{{\"bench\": \"mjcf_forge::Document::load(path).to_xml_string()\", \"files\": {}, \"bytes\": {bytes}, \"output_chars\": {out_chars}, \"runs\": {runs}, \"seconds\": {best:.6}, \"mb_per_s\": {:.3}}}",
        args.len(),
        bytes as f64 / 1e6 / best
    );
}
