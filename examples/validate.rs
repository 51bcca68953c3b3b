//! Validates MJCF files: `cargo run --example validate -- FILE...` prints every duplicate
//! name and dangling reference as `file:line:col: message`.

fn main() -> std::process::ExitCode {
    let mut failed = false;
    for path in std::env::args().skip(1) {
        match mjcf_forge::Document::load(&path)
            .map_err(|e| e.to_string())
            .and_then(|d| d.validate().map_err(|e| e.to_string()))
        {
            Ok(()) => {}
            Err(e) => {
                eprintln!("{e}");
                failed = true;
            }
        }
    }
    if failed {
        std::process::ExitCode::FAILURE
    } else {
        std::process::ExitCode::SUCCESS
    }
}
