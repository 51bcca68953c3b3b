//! Writes variants of a scene to a folder (a development aid until `generate` lands).
fn main() {
    let args: Vec<String> = std::env::args().collect();
    let scene = match args.get(1).map(String::as_str) {
        None | Some("demo") => mjcf_forge::scene::Scene::demo(),
        Some(p) => mjcf_forge::scene::Scene::load(p),
    };
    let scene = match scene {
        Ok(s) => s,
        Err(e) => {
            eprintln!("{e}");
            std::process::exit(1)
        }
    };
    let n: u64 = args.get(2).and_then(|a| a.parse().ok()).unwrap_or(5);
    let dir = std::path::PathBuf::from(args.get(3).cloned().unwrap_or("out/scene".into()));
    std::fs::create_dir_all(&dir).unwrap();
    for i in 0..n {
        match scene.variant(i) {
            Ok(v) => {
                std::fs::write(
                    dir.join(format!("{i:06}.xml")),
                    v.document.to_pretty_string(),
                )
                .unwrap();
                std::fs::write(dir.join(format!("{i:06}.json")), v.params_json()).unwrap();
            }
            Err(e) => eprintln!("{e}"),
        }
    }
}
