//! Times variant generation of a scene (development aid): `cargo run --release --example
//! variant_speed -- SCENE.toml N [xml]` prints the time per variant made as XML text on one
//! thread, through `variant_xml` (spliced) and through `variant` + writing its document;
//! with `xml`, only the spliced path (for profiling it alone).
fn main() {
    let args: Vec<String> = std::env::args().collect();
    let scene = mjcf_forge::scene::Scene::load(&args[1]).unwrap();
    let n: u64 = args[2].parse().unwrap();
    let t = std::time::Instant::now();
    let mut bytes = 0;
    for i in 0..n {
        bytes += scene.variant_xml(i).unwrap().0.len();
    }
    let spliced = t.elapsed().as_secs_f64();
    if args.get(3).is_some_and(|a| a == "xml") {
        println!("spliced: {:.1} us/variant", spliced * 1e6 / n as f64);
        return;
    }
    let t = std::time::Instant::now();
    for i in 0..n {
        bytes -= scene.variant(i).unwrap().xml().len();
    }
    let document = t.elapsed().as_secs_f64();
    assert_eq!(bytes, 0);
    println!(
        "spliced: {:.1} us/variant; document path: {:.1} us/variant",
        spliced * 1e6 / n as f64,
        document * 1e6 / n as f64
    );
}
