//! `info IN [--prefix P] [--json]`: a summary for a person, or the JSON object.

use std::path::PathBuf;
use std::process::ExitCode;

use mjcf_forge::{XmlModel, XmlModelOptions};

use super::{finish, write_stdout};

#[derive(clap::Args)]
pub struct Args {
    #[command(flatten)]
    limits: super::LimitArgs,
    #[command(flatten)]
    urdf: super::UrdfArgs,
    /// Input MJCF file (exactly one top-level body).
    input: PathBuf,
    /// Naming prefix of the instance (none by default).
    #[arg(long, default_value = "")]
    prefix: String,
    /// Print one JSON object (the same as Python's `Model.info_json()`) instead of the
    /// summary for a person.
    #[arg(long)]
    json: bool,
}

pub fn run(args: Args) -> ExitCode {
    let limits = super::Loader::new(&args.limits, &args.urdf);
    let result = limits
        .load(&args.input)
        .map_err(|e| e.to_string())
        .and_then(|doc| {
            let options = XmlModelOptions {
                contact_geom_rgba: None,
                ..XmlModelOptions::default()
            };
            let model =
                XmlModel::with_prefix(doc, &args.prefix, options).map_err(|e| e.to_string())?;
            let json = model.info_json();
            let text = if args.json {
                format!("{json}\n")
            } else {
                summary(&args.input.display().to_string(), &json)?
            };
            write_stdout(text.as_bytes())
        });
    finish(&[result])
}

/// The summary for a person, read off the JSON object so that the two forms always say
/// the same: one line per list (its count, then its names) and per offset.
fn summary(input: &str, json: &str) -> Result<String, String> {
    let info: serde_json::Value = serde_json::from_str(json)
        .map_err(|e| format!("{input}: cannot read the model's info: {e}"))?;
    let text = |key: &str| info[key].as_str().unwrap_or_default().to_owned();
    let mut out = String::new();
    let prefix = text("naming_prefix");
    out.push_str(&format!("model {} ({input})", text("name")));
    if !prefix.is_empty() {
        out.push_str(&format!(", prefix '{prefix}'"));
    }
    out.push('\n');
    let mut rows: Vec<(String, String)> = vec![("root body".into(), text("root_body"))];
    for (key, label) in [
        ("bodies", "bodies"),
        ("joints", "joints"),
        ("actuators", "actuators"),
        ("sites", "sites"),
        ("sensors", "sensors"),
        ("contact_geoms", "contact geoms"),
        ("visual_geoms", "visual geoms"),
    ] {
        let names: Vec<&str> = info[key]
            .as_array()
            .map(|a| a.iter().filter_map(|v| v.as_str()).collect())
            .unwrap_or_default();
        let list = if names.is_empty() {
            "-".to_owned()
        } else {
            names.join(" ")
        };
        rows.push((format!("{label} ({})", names.len()), list));
    }
    if let Some(e) = info["geometry_error"].as_str() {
        rows.push(("offsets".into(), format!("not computed: {e}")));
    } else {
        for (key, label) in [
            ("base_offset", "base offset"),
            ("bottom_offset", "bottom offset"),
            ("top_offset", "top offset"),
            ("horizontal_radius", "horizontal radius"),
        ] {
            let value = match &info[key] {
                serde_json::Value::Array(a) => a.iter().map(short).collect::<Vec<_>>().join(" "),
                v => short(v),
            };
            rows.push((label.into(), value));
        }
    }
    let width = rows.iter().map(|(k, _)| k.len()).max().unwrap_or(0);
    for (key, value) in rows {
        out.push_str(&format!("  {key:<width$}  {value}\n"));
    }
    Ok(out)
}

/// A number as a person reads it: six decimals at most, no trailing zeros (`0.43`, not
/// `0.4300000000000001`; the JSON keeps every digit).
fn short(value: &serde_json::Value) -> String {
    let Some(x) = value.as_f64() else {
        return value.to_string();
    };
    let text = format!("{x:.6}");
    let text = text.trim_end_matches('0').trim_end_matches('.');
    if text == "-0" {
        "0".to_owned()
    } else {
        text.to_owned()
    }
}
