//! Where each value of a RON document starts, by path (`tracks[2].translate[1].at`).
//!
//! serde hands the spec over without positions, but semantic errors (an unknown target, keys
//! out of order) must still point at the offending text. This is a small, forgiving RON
//! reader that records the position of every value; it never decides whether the document
//! is valid (ron does that first).

use anim_core::util::FastMap;

/// A 1-based line and column (columns in characters).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Pos {
    pub line: u32,
    pub col: u32,
}

/// Start position and length (in characters, for the caret) of every value, by path.
#[derive(Debug, Default)]
pub struct Locations {
    // Keyed by paths of the user's own file, not by an adversary probing collisions: the fast
    // hash, as for the scene reader's names.
    spans: FastMap<String, (Pos, u32)>,
    /// The name written before a value's parentheses (`Expr("…")`, `Frames(12)`) or alone
    /// (`AlongPath`), by path: serde passes over the names of some forms, which are checked
    /// against these.
    variants: FastMap<String, String>,
}

impl Locations {
    /// Scans `text`; a malformed document yields whatever was found before the problem.
    pub fn scan(text: &str) -> Locations {
        let mut s = Scanner {
            chars: text.chars().collect(),
            i: 0,
            line: 1,
            col: 1,
            out: Locations::default(),
        };
        s.skip_ws_and_attributes();
        s.value(String::new(), 0);
        s.out
    }

    /// The start and width of the value at `path`, e.g. `tracks[0].target`.
    pub fn get(&self, path: &str) -> Option<(Pos, u32)> {
        self.spans.get(path).copied()
    }

    /// The name written before the value at `path`, if one is: `Expr` of `Expr("…")`.
    pub fn variant(&self, path: &str) -> Option<&str> {
        self.variants.get(path).map(String::as_str)
    }

    /// The deepest (longest) path whose value starts at `pos`, with its width.
    pub fn starting_at(&self, pos: Pos) -> Option<(String, u32)> {
        self.spans
            .iter()
            .filter(|(_, (p, _))| *p == pos)
            .max_by(|a, b| a.0.len().cmp(&b.0.len()).then_with(|| b.0.cmp(a.0)))
            .map(|(path, (_, w))| (path.clone(), *w))
    }

    /// The value at the first of `paths` that exists (a field may be absent, its parent not).
    pub fn first(&self, paths: &[&str]) -> Option<(Pos, u32)> {
        paths.iter().find_map(|p| self.get(p))
    }
}

/// `parent.field`, or `field` at the top.
pub fn field(parent: &str, name: &str) -> String {
    if parent.is_empty() {
        name.to_string()
    } else {
        format!("{parent}.{name}")
    }
}

pub fn index(parent: &str, i: usize) -> String {
    format!("{parent}[{i}]")
}

struct Scanner {
    chars: Vec<char>,
    i: usize,
    line: u32,
    col: u32,
    out: Locations,
}

/// Deeper nesting than any spec needs; stops runaway recursion on hostile input.
const MAX_DEPTH: usize = 64;

impl Scanner {
    fn peek(&self) -> Option<char> {
        self.chars.get(self.i).copied()
    }

    fn peek_at(&self, k: usize) -> Option<char> {
        self.chars.get(self.i + k).copied()
    }

    fn bump(&mut self) -> Option<char> {
        let c = self.peek()?;
        self.i += 1;
        if c == '\n' {
            self.line += 1;
            self.col = 1;
        } else {
            self.col += 1;
        }
        Some(c)
    }

    fn pos(&self) -> Pos {
        Pos {
            line: self.line,
            col: self.col,
        }
    }

    fn skip_ws(&mut self) {
        loop {
            match (self.peek(), self.peek_at(1)) {
                (Some(c), _) if c.is_whitespace() => {
                    self.bump();
                }
                (Some('/'), Some('/')) => {
                    while let Some(c) = self.bump() {
                        if c == '\n' {
                            break;
                        }
                    }
                }
                (Some('/'), Some('*')) => {
                    // RON block comments nest.
                    self.bump();
                    self.bump();
                    let mut depth = 1;
                    while depth > 0 {
                        match (self.bump(), self.peek()) {
                            (None, _) => return,
                            (Some('/'), Some('*')) => {
                                self.bump();
                                depth += 1;
                            }
                            (Some('*'), Some('/')) => {
                                self.bump();
                                depth -= 1;
                            }
                            _ => {}
                        }
                    }
                }
                _ => return,
            }
        }
    }

    /// `#![enable(implicit_some)]` and similar attributes before the value.
    fn skip_ws_and_attributes(&mut self) {
        self.skip_ws();
        while self.peek() == Some('#') {
            let mut depth = 0i32;
            while let Some(c) = self.bump() {
                match c {
                    '[' => depth += 1,
                    ']' => {
                        depth -= 1;
                        if depth <= 0 {
                            break;
                        }
                    }
                    _ => {}
                }
            }
            self.skip_ws();
        }
    }

    fn record(&mut self, path: &str, start: Pos, start_i: usize) {
        let width = (self.i - start_i).clamp(1, 200) as u32;
        self.out
            .spans
            .entry(path.to_string())
            .or_insert((start, width));
    }

    fn ident(&mut self) -> String {
        let mut s = String::new();
        // `r#name` raw identifiers.
        if self.peek() == Some('r') && self.peek_at(1) == Some('#') {
            self.bump();
            self.bump();
        }
        while let Some(c) = self.peek() {
            if c.is_alphanumeric() || c == '_' {
                s.push(c);
                self.bump();
            } else {
                break;
            }
        }
        s
    }

    fn value(&mut self, path: String, depth: usize) {
        if depth > MAX_DEPTH {
            return;
        }
        self.skip_ws();
        let start = self.pos();
        let start_i = self.i;
        match self.peek() {
            None => {}
            Some('(') => {
                self.bump();
                self.contents(&path, ')', depth);
                self.record(&path, start, start_i);
            }
            Some('[') => {
                self.bump();
                self.contents(&path, ']', depth);
                self.record(&path, start, start_i);
            }
            Some('{') => {
                self.bump();
                self.map(&path, depth);
                self.record(&path, start, start_i);
            }
            Some('"') => {
                self.string();
                self.record(&path, start, start_i);
            }
            Some('r')
                if matches!(self.peek_at(1), Some('"') | Some('#')) && self.is_raw_string() =>
            {
                self.raw_string();
                self.record(&path, start, start_i);
            }
            Some('\'') => {
                self.bump();
                if self.peek() == Some('\\') {
                    self.bump();
                }
                self.bump();
                if self.peek() == Some('\'') {
                    self.bump();
                }
                self.record(&path, start, start_i);
            }
            Some(c) if c.is_alphabetic() || c == '_' => {
                let name = self.ident();
                if name != "Some" {
                    self.out
                        .variants
                        .entry(path.clone())
                        .or_insert(name.clone());
                }
                self.skip_ws();
                if self.peek() == Some('(') {
                    if name == "Some" {
                        // `Some(x)` and plain `x` mean the same with implicit_some: both
                        // are found at the same path.
                        self.bump();
                        self.value(path.clone(), depth + 1);
                        self.skip_ws();
                        if self.peek() == Some(',') {
                            self.bump();
                            self.skip_ws();
                        }
                        if self.peek() == Some(')') {
                            self.bump();
                        }
                    } else {
                        self.bump();
                        self.contents(&path, ')', depth);
                    }
                }
                self.record(&path, start, start_i);
            }
            Some(_) => {
                // Numbers and anything unexpected: up to the next delimiter.
                while let Some(c) = self.peek() {
                    if c.is_whitespace()
                        || matches!(c, ',' | ')' | ']' | '}' | ':' | '(' | '[' | '{')
                    {
                        break;
                    }
                    self.bump();
                }
                if self.i == start_i {
                    // An unexpected delimiter: consume it so scanning makes progress.
                    self.bump();
                }
                self.record(&path, start, start_i);
            }
        }
    }

    fn is_raw_string(&self) -> bool {
        let mut k = 1;
        while self.peek_at(k) == Some('#') {
            k += 1;
        }
        self.peek_at(k) == Some('"')
    }

    fn string(&mut self) {
        self.bump();
        while let Some(c) = self.bump() {
            match c {
                '\\' => {
                    self.bump();
                }
                '"' => return,
                _ => {}
            }
        }
    }

    fn raw_string(&mut self) {
        self.bump(); // r
        let mut hashes = 0;
        while self.peek() == Some('#') {
            self.bump();
            hashes += 1;
        }
        self.bump(); // "
        while let Some(c) = self.bump() {
            if c == '"' {
                let mut k = 0;
                while k < hashes && self.peek_at(k) == Some('#') {
                    k += 1;
                }
                if k == hashes {
                    for _ in 0..hashes {
                        self.bump();
                    }
                    return;
                }
            }
        }
    }

    /// The inside of `( … )` or `[ … ]`: named fields (`name: value`) or positional elements.
    fn contents(&mut self, path: &str, close: char, depth: usize) {
        let mut n = 0;
        loop {
            self.skip_ws();
            match self.peek() {
                None => return,
                Some(c) if c == close => {
                    self.bump();
                    return;
                }
                Some(',') => {
                    self.bump();
                    continue;
                }
                _ => {}
            }
            let before = self.i;
            if close == ')' && self.field_follows() {
                let name = self.ident();
                self.skip_ws();
                self.bump(); // ':'
                self.value(field(path, &name), depth + 1);
            } else {
                self.value(index(path, n), depth + 1);
                n += 1;
            }
            if self.i == before {
                self.bump();
            }
        }
    }

    /// Whether an identifier followed by `:` starts here (a struct field).
    fn field_follows(&self) -> bool {
        let mut k = 0;
        if self.peek() == Some('r') && self.peek_at(1) == Some('#') {
            k = 2;
        }
        let start = k;
        while let Some(c) = self.peek_at(k) {
            if c.is_alphanumeric() || c == '_' {
                k += 1;
            } else {
                break;
            }
        }
        if k == start || self.peek_at(start).is_some_and(|c| c.is_ascii_digit()) {
            return false;
        }
        while self.peek_at(k).is_some_and(|c| c == ' ' || c == '\t') {
            k += 1;
        }
        self.peek_at(k) == Some(':')
    }

    fn map(&mut self, path: &str, depth: usize) {
        let mut n = 0;
        loop {
            self.skip_ws();
            match self.peek() {
                None => return,
                Some('}') => {
                    self.bump();
                    return;
                }
                Some(',') => {
                    self.bump();
                    continue;
                }
                _ => {}
            }
            let before = self.i;
            self.value(format!("{path}{{key {n}}}"), depth + 1);
            self.skip_ws();
            if self.peek() == Some(':') {
                self.bump();
                self.value(index(path, n), depth + 1);
            }
            n += 1;
            if self.i == before {
                self.bump();
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_nested_values() {
        let text = "#![enable(implicit_some)]\n(\n  a: 1, // c\n  /* x /* y */ */ b: [ (t: \"x\"), Some((t: r#\"q\"#)) ],\n  c: File(\"s.sdf\"),\n)";
        let l = Locations::scan(text);
        assert_eq!(l.get("a").unwrap().0, Pos { line: 3, col: 6 });
        assert_eq!(l.get("b[0].t").unwrap().0, Pos { line: 4, col: 28 });
        assert_eq!(l.get("b[1].t").unwrap().0, Pos { line: 4, col: 43 });
        assert_eq!(l.get("c[0]").unwrap(), (Pos { line: 5, col: 11 }, 7));
        assert_eq!(l.get("c").unwrap().0, Pos { line: 5, col: 6 });
    }

    #[test]
    fn survives_garbage() {
        for text in ["(", "((((", ")]}", "(a: [1, (b: ", "r#\"", "'", "(a: 'x"] {
            let _ = Locations::scan(text);
        }
    }
}
