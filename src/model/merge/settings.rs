//! The model-wide settings a part brings (`option`, `size`, `visual`, `statistic`): the
//! base's win, and each of the part's they override becomes a warning.

use super::{MergeReport, same_value};
use crate::document::Document;
use crate::document::tree::Node;

impl Document {
    /// `option`/`size`/`visual`/`statistic` of a part: the base's values win; every part
    /// setting the base does not share is reported. `size` user-data widths take the larger.
    pub(super) fn settings_from_part(
        &mut self,
        part: &Document,
        section: Node,
        report: &mut MergeReport,
    ) {
        let tag = part.tag(section).to_string();
        let base = self.elements(self.root).find(|&n| self.tag(n) == tag);
        let mut items: Vec<(Node, Option<Node>)> = vec![(section, base)];
        while let Some((p, b)) = items.pop() {
            for (k, v) in part.attrs(p) {
                let bv = b.and_then(|b| self.attr(b, k)).map(str::to_string);
                if tag == "size" && k.starts_with("nuser_") {
                    let pv: i64 = v.trim().parse().unwrap_or(-1);
                    let cur: i64 = bv
                        .as_deref()
                        .and_then(|x| x.trim().parse().ok())
                        .unwrap_or(-1);
                    if pv > cur {
                        let b = match b {
                            Some(b) => b,
                            None => {
                                let n = self.append_element(self.root, "size", &[]);
                                items.retain(|_| true);
                                n
                            }
                        };
                        self.set_attr(b, k, v);
                        report.warnings.push(format!(
                            "{}: <size {k}=\"{v}\"> of the part is used (the larger user-data width)",
                            part.location(p)
                        ));
                    }
                    continue;
                }
                if bv.as_deref().is_some_and(|bv| same_value(bv, v)) {
                    continue;
                }
                report.warnings.push(format!(
                    "{}: the part's <{} {k}=\"{v}\"> is ignored: the base's {} wins",
                    part.location(p),
                    part.tag(p),
                    bv.map(|x| format!("\"{x}\""))
                        .unwrap_or_else(|| "value (MuJoCo's default)".into())
                ));
            }
            for pk in part.elements(p) {
                let t = part.tag(pk);
                let bk = b.and_then(|b| self.elements(b).find(|&x| self.tag(x) == t));
                items.push((pk, bk));
            }
        }
    }
}
