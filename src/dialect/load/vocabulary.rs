//! Loading `<vocabulary>`: the control's documented codes, cycles, statements and forms that
//! the engine does not model, each kept as intent or known unsupported, with its manual.

use super::super::vocabulary::{Entry, Kind, Status, Vocabulary, parse_ranges};
use super::super::xml::Element;
use super::Cx;

impl Cx {
    pub(super) fn vocabulary(&mut self, el: &Element) -> Vocabulary {
        self.shape(el, &["manual"], &["entry", "remove"]);
        let manual = self.attr(el, "manual").unwrap_or_default().to_owned();
        let mut entries = Vec::new();
        for e in el.children.iter().filter(|c| c.name == "entry") {
            self.shape(e, &["kind", "codes", "status", "what", "manual", "moves"], &[]);
            let (Some(kind), Some(codes), Some(status)) = (self.required(e, "kind"), self.required(e, "codes"), self.required(e, "status"))
            else {
                continue;
            };
            let Some(kind) = Kind::parse(kind) else {
                self.error(Self::attr_range(e, "kind"), format!("unknown vocabulary kind `{kind}`"));
                continue;
            };
            let status = match status {
                "intent" => Status::Intent,
                "unsupported" => Status::Unsupported,
                "modelled" => Status::Modelled,
                other => {
                    self.error(Self::attr_range(e, "status"), format!("`status` is intent, unsupported or modelled, not `{other}`"));
                    continue;
                }
            };
            let ranges = if matches!(kind, Kind::G | Kind::M | Kind::SystemVariable) {
                match parse_ranges(codes) {
                    Some(r) => r,
                    None => {
                        self.error(
                            Self::attr_range(e, "codes"),
                            format!("`codes` must be numbers and ranges (`12.1 100-199`), not `{codes}`"),
                        );
                        continue;
                    }
                }
            } else {
                Vec::new()
            };
            let what = self.attr(e, "what").unwrap_or_default().to_owned();
            let manual = self.attr(e, "manual").map_or_else(|| manual.clone(), str::to_owned);
            let moves = self.bool(e, "moves", false);
            entries.push(Entry { kind, codes: codes.to_owned(), ranges, status, what, manual, moves });
        }
        Vocabulary { manual, entries }
    }
}
