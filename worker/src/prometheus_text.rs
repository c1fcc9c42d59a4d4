//! The Prometheus text exposition format (version 0.0.4), written by hand: a family is its
//! `# HELP` and `# TYPE` lines and one line per sample, `name{labels} value`. The worker's
//! `/metrics` (`metrics.rs`) and the coordinator's status page write theirs with it; a few
//! dozen families need no registry.

use std::fmt::{Display, Write};

pub const CONTENT_TYPE: &str = "text/plain; version=0.0.4; charset=utf-8";

/// What a family's samples are.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MetricType {
    /// Only goes up (from 0 when the process starts).
    Counter,
    /// Goes up and down.
    Gauge,
}

impl MetricType {
    pub fn name(self) -> &'static str {
        match self {
            MetricType::Counter => "counter",
            MetricType::Gauge => "gauge",
        }
    }
}

/// An exposition being written.
#[derive(Default)]
pub struct Exposition {
    text: String,
}

impl Exposition {
    pub fn new() -> Self {
        Self::default()
    }

    /// One family: its help and type, then a line per sample (its labels as [`labels`]
    /// writes them, or empty, and its value).
    pub fn family<V: Display>(
        &mut self,
        name: &str,
        kind: MetricType,
        help: &str,
        samples: impl IntoIterator<Item = (String, V)>,
    ) {
        let help = help.replace('\\', "\\\\").replace('\n', "\\n");
        let _ = writeln!(self.text, "# HELP {name} {help}");
        let _ = writeln!(self.text, "# TYPE {name} {}", kind.name());
        for (labels, value) in samples {
            let _ = writeln!(self.text, "{name}{labels} {value}");
        }
    }

    /// A family of one sample without labels.
    pub fn single(&mut self, name: &str, kind: MetricType, help: &str, value: impl Display) {
        self.family(name, kind, help, [(String::new(), value)]);
    }

    pub fn finish(self) -> String {
        self.text
    }
}

/// `{a="x",b="y"}` with the values escaped as the format asks (backslash, quote, newline).
pub fn labels(pairs: &[(&str, &str)]) -> String {
    let body: Vec<String> = pairs
        .iter()
        .map(|(name, value)| {
            let value = value
                .replace('\\', "\\\\")
                .replace('"', "\\\"")
                .replace('\n', "\\n");
            format!("{name}=\"{value}\"")
        })
        .collect();
    format!("{{{}}}", body.join(","))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn families_samples_and_escapes() {
        let mut out = Exposition::new();
        out.single(
            "a_total",
            MetricType::Counter,
            "Things.\nMore \\ things.",
            3u64,
        );
        out.family(
            "b",
            MetricType::Gauge,
            "Bees.",
            [
                (labels(&[("x", "q\"uo\\te\nd"), ("y", "2")]), 0.25),
                (labels(&[("x", "plain")]), 1.0),
            ],
        );
        out.family(
            "c",
            MetricType::Gauge,
            "None yet.",
            Vec::<(String, f64)>::new(),
        );
        assert_eq!(
            out.finish(),
            "# HELP a_total Things.\\nMore \\\\ things.\n# TYPE a_total counter\na_total 3\n\
             # HELP b Bees.\n# TYPE b gauge\nb{x=\"q\\\"uo\\\\te\\nd\",y=\"2\"} 0.25\n\
             b{x=\"plain\"} 1\n# HELP c None yet.\n# TYPE c gauge\n"
        );
    }
}
