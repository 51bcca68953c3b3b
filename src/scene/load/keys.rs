//! Key paths for a description that has no text of its own (a Python `dict`, JSON): it is
//! read as the TOML text it serializes to, and every position in that text is told as the
//! key path of the value there (`objects[0].placement.x`), which is what its author wrote.

use std::ops::Range;
use std::sync::Arc;

use toml::Spanned;
use toml::de::{DeTable, DeValue};

/// The key path of every key and value of a TOML text, by its byte span.
pub(crate) struct KeyPaths {
    /// `(span, path)` of each key and value, parents before their children.
    spans: Vec<(Range<usize>, Arc<String>)>,
}

impl KeyPaths {
    /// The paths of `text`; `None` when it does not parse (it is what the serializer wrote,
    /// so it does: the caller then reports lines and columns).
    pub(crate) fn of(text: &str) -> Option<KeyPaths> {
        let table = DeTable::parse(text).ok()?;
        let mut spans = vec![(table.span(), Arc::new(String::new()))];
        walk_table(table.get_ref(), "", &mut spans);
        Some(KeyPaths { spans })
    }

    /// The path of the innermost key or value that holds `span` (the whole description's
    /// empty path when none does).
    pub(crate) fn at(&self, span: Range<usize>) -> Arc<String> {
        let mut best: Option<&(Range<usize>, Arc<String>)> = None;
        for entry in &self.spans {
            let (r, _) = entry;
            let holds = r.start <= span.start && span.end <= r.end.max(r.start + 1);
            // The innermost: the shortest span; on a tie the later (deeper) entry.
            if holds && best.is_none_or(|(b, _)| r.len() <= b.len()) {
                best = Some(entry);
            }
        }
        best.map_or_else(|| Arc::new(String::new()), |(_, p)| p.clone())
    }
}

/// `path.key`, with the key quoted when it is not a plain identifier.
pub(crate) fn join(path: &str, key: &str) -> String {
    let plain = !key.is_empty()
        && key
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-');
    match (path.is_empty(), plain) {
        (true, true) => key.to_string(),
        (false, true) => format!("{path}.{key}"),
        (_, false) => format!("{path}[{key:?}]"),
    }
}

fn walk_table(table: &DeTable<'_>, path: &str, out: &mut Vec<(Range<usize>, Arc<String>)>) {
    for (key, value) in table {
        let here = join(path, key.get_ref());
        let here = Arc::new(here);
        out.push((key.span(), here.clone()));
        walk(value, &here, out);
    }
}

fn walk(
    value: &Spanned<DeValue<'_>>,
    path: &Arc<String>,
    out: &mut Vec<(Range<usize>, Arc<String>)>,
) {
    out.push((value.span(), path.clone()));
    match value.get_ref() {
        DeValue::Table(t) => walk_table(t, path, out),
        DeValue::Array(items) => {
            for (i, item) in items.iter().enumerate() {
                walk(item, &Arc::new(format!("{path}[{i}]")), out);
            }
        }
        _ => {}
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_span_is_told_by_the_innermost_key_path_that_holds_it() {
        let text = "seed = 1\n[[objects]]\nname = \"a\"\n[objects.placement]\nx = [0, \"b\"]\n";
        let keys = KeyPaths::of(text).unwrap();
        let at = |needle: &str| {
            let start = text.find(needle).unwrap();
            keys.at(start..start + needle.len()).to_string()
        };
        assert_eq!(at("1"), "seed");
        assert_eq!(at("\"a\""), "objects[0].name");
        assert_eq!(at("[0, \"b\"]"), "objects[0].placement.x");
        assert_eq!(at("\"b\""), "objects[0].placement.x[1]");
        assert_eq!(join("a", "b c"), "a[\"b c\"]");
    }
}

#[cfg(test)]
mod scene_errors {
    use crate::scene::Scene;

    /// Every bad scene file of the corpus, given as a dict (JSON): the same problems, each
    /// told by the key path of its value instead of a line and column.
    #[test]
    fn every_bad_scene_given_as_a_dict_names_its_keys() {
        let dir = std::path::Path::new("corpora/scenes/errors");
        let mut cases: Vec<_> = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().path())
            .filter(|p| p.extension().is_some_and(|e| e == "toml"))
            .collect();
        cases.sort();
        assert!(cases.len() >= 10);
        let mut seen = Vec::new();
        for case in cases {
            let text = std::fs::read_to_string(&case).unwrap();
            let value: toml::Value = toml::from_str(&text).unwrap();
            let json = serde_json::to_string(&value).unwrap();
            // A scene that loads fails at its variants (a region too small for its group).
            let problems = |scene: Result<Scene, crate::Errors>| match scene {
                Err(e) => e,
                Ok(scene) => match scene.variant(0) {
                    Err(e) => e,
                    Ok(_) => panic!("{}: no problem", case.display()),
                },
            };
            let from_file = problems(Scene::load(&case));
            let from_dict = problems(Scene::from_json_str(&json, dir));
            // A message may quote a location itself (a randomizer's): the file's or the key's.
            let file = case.display().to_string();
            let unplaced = |message: String, at: &str| match message.find(at) {
                Some(i) => {
                    let rest = &message[i + at.len()..];
                    let end = rest.find(": ").map_or(rest.len(), |j| j);
                    format!("{}@{}", &message[..i], &rest[end..])
                }
                None => message,
            };
            let mut want: Vec<String> = from_file
                .0
                .iter()
                .map(|e| unplaced(e.kind.to_string(), &file))
                .collect();
            let mut got: Vec<String> = from_dict
                .0
                .iter()
                .map(|e| unplaced(e.kind.to_string(), "<scene dict>: "))
                .collect();
            want.sort();
            got.sort();
            assert_eq!(got, want, "{}", case.display());
            for e in &from_dict.0 {
                // Problems inside a model file keep that file's position.
                let at = e.location.as_ref().expect("positioned");
                if &*at.file == std::path::Path::new("<scene dict>") {
                    let line = e.to_string();
                    assert!(line.starts_with("<scene dict>: "), "{line}");
                    seen.push(line);
                }
            }
        }
        for line in [
            "<scene dict>: fixtures: unknown field `fixtures`, expected one of `seed`, `base`, `discard_visual`, `fixture`, `objects`, `randomize`",
            "<scene dict>: objects[0].count: invalid type: string \"three\", expected a count: a whole number, or [min, max]",
            "<scene dict>: objects[0].placement.x: x must be [min, max] with min <= max",
            "<scene dict>: objects[0].pool[0]: a weight must be a finite number >= 0",
            "<scene dict>: fixture[0].model: cannot read 'corpora/scenes/errors/../demo/no_such_robot.xml': No such file or directory (os error 2)",
        ] {
            assert!(
                seen.iter().any(|s| s == line),
                "{line} not in\n{}",
                seen.join("\n")
            );
        }
    }

    #[test]
    fn nulls_and_non_tables_are_named() {
        let err = Scene::from_json_str(
            r#"{"base": "arena.xml", "objects": [{"prefix": null}]}"#,
            ".",
        )
        .unwrap_err();
        assert_eq!(
            err.to_string(),
            "<scene dict>: objects[0].prefix: null (None) is not a value: leave the key out"
        );
        let err = Scene::from_json_str("[1]", ".").unwrap_err();
        assert_eq!(
            err.to_string(),
            "<scene dict>: a scene description is a table (a dict) of its keys"
        );
    }
}
