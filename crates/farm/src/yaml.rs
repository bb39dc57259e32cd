//! A small YAML writer for the job template (docs/farm.md, "Schedulers"): block mappings and
//! sequences, strings double-quoted with JSON's escapes (which YAML's double-quoted scalars
//! share), integers plain, and scripts as literal blocks so they read as they run.

use std::fmt::Write as _;

/// A YAML value.
#[derive(Clone, Debug, PartialEq)]
pub enum Node {
    /// A string, always quoted.
    Str(String),
    /// An integer.
    Int(i64),
    /// A boolean.
    Bool(bool),
    /// A multi-line text, written as a literal block (`|`).
    Block(String),
    /// A sequence.
    List(Vec<Node>),
    /// A mapping, its keys in order.
    Map(Vec<(&'static str, Node)>),
}

/// A string node.
pub fn s(v: impl Into<String>) -> Node {
    Node::Str(v.into())
}

/// `node` as a YAML document.
pub fn document(node: &Node) -> String {
    let mut out = String::new();
    match node {
        Node::Map(entries) => map(&mut out, entries, 0, false),
        other => value(&mut out, other, 0),
    }
    out
}

fn scalar(node: &Node) -> Option<String> {
    match node {
        // A JSON string is a valid YAML double-quoted scalar.
        Node::Str(v) => Some(serde_json::Value::String(v.clone()).to_string()),
        Node::Int(v) => Some(v.to_string()),
        Node::Bool(v) => Some(v.to_string()),
        _ => None,
    }
}

fn pad(out: &mut String, indent: usize) {
    out.extend(std::iter::repeat_n(' ', indent));
}

/// A mapping at `indent`; `inline` when its first key follows a `- ` already written.
fn map(out: &mut String, entries: &[(&'static str, Node)], indent: usize, inline: bool) {
    if entries.is_empty() {
        out.push_str("{}\n");
        return;
    }
    for (n, (key, v)) in entries.iter().enumerate() {
        if n > 0 || !inline {
            pad(out, indent);
        }
        let _ = write!(out, "{key}:");
        match v {
            Node::Map(inner) if !inner.is_empty() => {
                out.push('\n');
                map(out, inner, indent + 2, false);
            }
            Node::List(items) if !items.is_empty() => {
                out.push('\n');
                list(out, items, indent + 2);
            }
            other => {
                out.push(' ');
                value(out, other, indent + 2);
            }
        }
    }
}

fn list(out: &mut String, items: &[Node], indent: usize) {
    for item in items {
        pad(out, indent);
        out.push_str("- ");
        match item {
            Node::Map(entries) => map(out, entries, indent + 2, true),
            other => value(out, other, indent + 2),
        }
    }
}

/// A scalar, block or empty collection after `key: ` or `- `.
fn value(out: &mut String, node: &Node, indent: usize) {
    if let Some(text) = scalar(node) {
        let _ = writeln!(out, "{text}");
        return;
    }
    match node {
        Node::Block(text) => {
            out.push_str(if text.ends_with('\n') { "|\n" } else { "|-\n" });
            for line in text.lines() {
                if !line.is_empty() {
                    pad(out, indent);
                    out.push_str(line);
                }
                out.push('\n');
            }
        }
        Node::List(items) if items.is_empty() => out.push_str("[]\n"),
        Node::List(items) => {
            out.push('\n');
            list(out, items, indent);
        }
        Node::Map(entries) => {
            out.push('\n');
            map(out, entries, indent, false);
        }
        Node::Str(_) | Node::Int(_) | Node::Bool(_) => {}
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn writes_block_yaml() {
        let doc = Node::Map(vec![
            ("name", s("a \"shot\"")),
            ("n", Node::Int(3)),
            (
                "steps",
                Node::List(vec![Node::Map(vec![
                    ("name", s("x")),
                    ("args", Node::List(vec![s("a b"), s("c")])),
                ])]),
            ),
            ("data", Node::Block("line 1\n  line 2\n".into())),
            ("empty", Node::List(vec![])),
        ]);
        assert_eq!(
            document(&doc),
            "name: \"a \\\"shot\\\"\"\nn: 3\nsteps:\n  - name: \"x\"\n    args:\n      - \"a b\"\n      - \"c\"\n\
             data: |\n  line 1\n    line 2\nempty: []\n"
        );
    }
}
