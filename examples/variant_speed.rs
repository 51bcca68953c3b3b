//! Times variant generation of a scene (development aid): `cargo run --release --example
//! variant_speed -- SCENE.toml N`.
use rayon::prelude::*;
fn main() {
    let args: Vec<String> = std::env::args().collect();
    let scene = mjcf_forge::scene::Scene::load(&args[1]).unwrap();
    let n: u64 = args[2].parse().unwrap();
    let t = std::time::Instant::now();
    let mut bytes = 0;
    for i in 0..n {
        bytes += scene.variant(i).unwrap().xml().len();
    }
    let one = t.elapsed().as_secs_f64();
    let t = std::time::Instant::now();
    let b2: usize = (0..n)
        .into_par_iter()
        .map(|i| scene.variant(i).unwrap().xml().len())
        .sum();
    let all = t.elapsed().as_secs_f64();
    let t = std::time::Instant::now();
    for i in 0..n {
        std::hint::black_box(scene.variant(i).unwrap());
    }
    let nowrite = t.elapsed().as_secs_f64();
    println!(
        "1 thread: {:.1} us/variant ({:.0}/s), no write {:.1} us; all threads {:.0}/s; {} bytes avg",
        one * 1e6 / n as f64,
        n as f64 / one,
        nowrite * 1e6 / n as f64,
        n as f64 / all,
        bytes / n as usize
    );
    assert_eq!(bytes, b2);
}
