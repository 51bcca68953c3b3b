//! What was drawn for a variant, and its manifest line.

use std::fmt::Write as _;

/// Everything drawn for one variant.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Params {
    /// The objects placed, in the order of the groups and their slots.
    pub objects: Vec<PlacedObject>,
    /// Every randomized attribute, in the order applied.
    pub randomized: Vec<RandomizedValue>,
}

/// One placed object.
#[derive(Clone, Debug, PartialEq)]
pub struct PlacedObject {
    /// Its group's name.
    pub group: String,
    /// Its slot in the group (the `{i}` of the prefix).
    pub slot: u32,
    /// The model file, as the scene file names it.
    pub model: String,
    /// The prefix of its names.
    pub prefix: String,
    /// Its root body's name.
    pub body: String,
    /// The root body's position, as written in the XML.
    pub pos: String,
    /// The root body's orientation (w x y z), as written in the XML.
    pub quat: String,
}

/// One randomized attribute of one element.
#[derive(Clone, Debug, PartialEq)]
pub struct RandomizedValue {
    /// The element's tag.
    pub kind: String,
    /// The element's name (with its prefix), if it has one.
    pub name: Option<String>,
    /// The part it belongs to: `base`, a fixture's prefix, an object group's name.
    pub part: String,
    /// The attribute.
    pub attribute: String,
    /// The value written, exactly as in the XML.
    pub value: String,
}

impl Params {
    /// One line of JSON: `{"index":..,"file":..,"objects":[..],"randomized":[..]}` (no
    /// newline); `file` only when given.
    ///
    /// ```
    /// let p = mjcf_forge::scene::Params::default();
    /// assert_eq!(p.to_json(4, Some("000004.xml")), r#"{"index":4,"file":"000004.xml","objects":[],"randomized":[]}"#);
    /// ```
    pub fn to_json(&self, index: u64, file: Option<&str>) -> String {
        let mut out =
            String::with_capacity(128 + 160 * (self.objects.len() + self.randomized.len()));
        self.write_json(index, file, &mut out);
        out
    }

    /// [`Params::to_json`] appended to `out` (for a buffer that is reused).
    ///
    /// ```
    /// let p = mjcf_forge::scene::Params::default();
    /// let mut line = String::from("> ");
    /// p.write_json(4, None, &mut line);
    /// assert_eq!(line, format!("> {}", p.to_json(4, None)));
    /// ```
    pub fn write_json(&self, index: u64, file: Option<&str>, out: &mut String) {
        let _ = write!(out, "{{\"index\":{index}");
        if let Some(f) = file {
            out.push_str(",\"file\":");
            json_str(out, f);
        }
        out.push_str(",\"objects\":[");
        for (i, o) in self.objects.iter().enumerate() {
            if i > 0 {
                out.push(',');
            }
            out.push_str("{\"group\":");
            json_str(out, &o.group);
            let _ = write!(out, ",\"slot\":{}", o.slot);
            out.push_str(",\"model\":");
            json_str(out, &o.model);
            out.push_str(",\"prefix\":");
            json_str(out, &o.prefix);
            out.push_str(",\"body\":");
            json_str(out, &o.body);
            out.push_str(",\"pos\":");
            json_str(out, &o.pos);
            out.push_str(",\"quat\":");
            json_str(out, &o.quat);
            out.push('}');
        }
        out.push_str("],\"randomized\":[");
        for (i, r) in self.randomized.iter().enumerate() {
            if i > 0 {
                out.push(',');
            }
            out.push_str("{\"kind\":");
            json_str(out, &r.kind);
            out.push_str(",\"name\":");
            match &r.name {
                Some(n) => json_str(out, n),
                None => out.push_str("null"),
            }
            out.push_str(",\"part\":");
            json_str(out, &r.part);
            out.push_str(",\"attribute\":");
            json_str(out, &r.attribute);
            out.push_str(",\"value\":");
            json_str(out, &r.value);
            out.push('}');
        }
        out.push_str("]}");
    }
}

/// A JSON string literal (RFC 8259 escapes).
fn json_str(out: &mut String, s: &str) {
    out.push('"');
    // Names, numbers and paths rarely need escapes: copy them whole when they do not.
    if !s.bytes().any(|b| b < 0x20 || b == b'"' || b == b'\\') {
        out.push_str(s);
        out.push('"');
        return;
    }
    for c in s.chars() {
        match c {
            '"' => out.push_str("\\\""),
            '\\' => out.push_str("\\\\"),
            '\n' => out.push_str("\\n"),
            '\r' => out.push_str("\\r"),
            '\t' => out.push_str("\\t"),
            c if (c as u32) < 0x20 => {
                let _ = write!(out, "\\u{:04x}", c as u32);
            }
            c => out.push(c),
        }
    }
    out.push('"');
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn json_reads_back_with_serde() {
        let p = Params {
            objects: vec![PlacedObject {
                group: "g\"1".into(),
                slot: 2,
                model: "a\\b.xml".into(),
                prefix: "g2_".into(),
                body: "g2_box".into(),
                pos: "0 0.1 0.2".into(),
                quat: "1 0 0 0".into(),
            }],
            randomized: vec![RandomizedValue {
                kind: "geom".into(),
                name: None,
                part: "base".into(),
                attribute: "rgba".into(),
                value: "1 0 0\t1\u{1}".into(),
            }],
        };
        let v: serde_json::Value = serde_json::from_str(&p.to_json(9, Some("x.xml"))).unwrap();
        assert_eq!(v["index"], 9);
        assert_eq!(v["objects"][0]["group"], "g\"1");
        assert_eq!(v["objects"][0]["model"], "a\\b.xml");
        assert_eq!(v["randomized"][0]["name"], serde_json::Value::Null);
        assert_eq!(v["randomized"][0]["value"], "1 0 0\t1\u{1}");
    }
}
