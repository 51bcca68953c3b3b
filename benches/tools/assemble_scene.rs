//! Assembles the Lift-like scene of `benches/model.rs` N times (for profiling and the
//! same-run comparison with robosuite): `cargo run --release --example assemble_scene -- 100`.
//! With `NO_WRITE` set, the scenes are not written out.

#[path = "../lift_scene.rs"]
mod lift_scene;
use lift_scene::{assemble, parts};

fn main() {
    let n: usize = std::env::args()
        .nth(1)
        .and_then(|a| a.parse().ok())
        .unwrap_or(100);
    let p = parts();
    let start = std::time::Instant::now();
    let mut bytes = 0;
    for _ in 0..n {
        let scene = assemble(&p);
        if std::env::var_os("NO_WRITE").is_none() {
            bytes += scene.to_xml_string().len();
        } else {
            bytes += scene.node_count();
        }
    }
    println!(
        "{n} scenes, {bytes} bytes, {:.1} us per scene",
        start.elapsed().as_secs_f64() * 1e6 / n as f64
    );
}
