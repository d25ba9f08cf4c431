//! Splitting SDF text into lines and tokens, and reading numbers.
//!
//! The language is line oriented: a line is a list of tokens separated by runs of whitespace,
//! `#` starts a comment anywhere, and a line whose first token starts with `//` is a comment.
//! Columns count characters from 1, so a caret can be placed under any token even in lines
//! with non-ASCII names (`jklö`).

/// Numbers beyond this magnitude are rejected: they are never meant, and squaring them (as
/// ray/sphere tests do) would overflow to infinity in the renderer.
pub const MAX_MAGNITUDE: f64 = 1e12;

/// One whitespace-separated word of a line.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Token<'a> {
    pub text: &'a str,
    /// 1-based column of the first character, counted in characters.
    pub col: u32,
    /// Length in characters.
    pub width: u32,
}

/// A source line with its comments removed.
#[derive(Clone, Debug)]
pub struct Line<'a> {
    /// 1-based line number.
    pub number: u32,
    /// The whole line as written, without its line ending.
    pub text: &'a str,
    pub tokens: Vec<Token<'a>>,
}

impl Line<'_> {
    /// The column just after the last token: where a missing argument would have gone.
    pub fn end_col(&self) -> u32 {
        self.tokens
            .last()
            .map_or(1, |t| t.col.saturating_add(t.width))
    }
}

/// Splits a whole file into lines and tokenizes each. LF, CRLF and a lone CR (old Mac files)
/// all end a line; the final line ending is optional. A byte-order mark at the start of the
/// file is ignored. The reader goes through a file with [`each_line`] instead, which keeps no
/// more than one line's tokens.
#[cfg(test)]
pub fn lines(text: &str) -> Vec<Line<'_>> {
    raw_lines(text)
        .enumerate()
        .map(|(i, raw)| Line {
            number: line_number(i),
            text: raw,
            tokens: tokenize(raw),
        })
        .collect()
}

/// Calls `f` with every line of `text` (as [`lines`] splits them), tokenized into one buffer
/// that is reused from line to line: reading a file of a million lines allocates no token
/// list per line, and never holds more than one. A line of ASCII is split from the text and
/// tokenized in the same pass over its bytes.
pub fn each_line<'t>(text: &'t str, mut f: impl FnMut(&Line<'t>)) {
    let mut tokens = Vec::new();
    let mut rest = text.strip_prefix('\u{feff}').unwrap_or(text);
    let mut i = 0;
    // A final line ending does not start another line.
    while !rest.is_empty() {
        let (end, skip) = scan_line(rest, &mut tokens);
        let line = Line {
            number: line_number(i),
            text: &rest[..end],
            tokens,
        };
        f(&line);
        tokens = line.tokens;
        rest = &rest[end + skip..];
        i += 1;
    }
}

/// Tokenizes the first line of `rest` into `tokens` (as [`tokenize_into`] does); the line's
/// length in bytes and the length of its line ending.
fn scan_line<'t>(rest: &'t str, tokens: &mut Vec<Token<'t>>) -> (usize, usize) {
    tokens.clear();
    let bytes = rest.as_bytes();
    let class = |i: usize| bytes.get(i).map_or(END, |&b| BYTE_CLASS[usize::from(b)]);
    // The end of the run of bytes of class `c` from `from` (at most the end of the text):
    // a search over the slice, which compiles to a tighter loop than testing `class(i)`.
    let run = |from: usize, c: u8| {
        bytes
            .get(from..)
            .and_then(|tail| tail.iter().position(|&b| BYTE_CLASS[usize::from(b)] != c))
            .map_or(bytes.len(), |n| from + n)
    };
    // The end of a word: eight bytes at a time where the text holds eight more, so that a
    // word (rarely longer) costs one test whose outcome is predictable, not one per byte.
    let word_end = |mut i: usize| {
        while let Some(Ok(chunk)) = bytes.get(i..i + 8).map(<[u8; 8]>::try_from) {
            let stop = non_word_bytes(u64::from_le_bytes(chunk));
            if stop != 0 {
                return i + (stop.trailing_zeros() / 8) as usize;
            }
            i += 8;
        }
        run(i, WORD)
    };
    let mut i = 0;
    loop {
        i = run(i, SPACE);
        let start = i;
        i = word_end(i);
        if i > start && tokens.len() < crate::limits::MAX_TOKENS_PER_LINE {
            // Past the cap the rest is not kept (see `overlong`, by which the line is
            // reported).
            tokens.push(Token {
                text: &rest[start..i],
                col: u32::try_from(start + 1).unwrap_or(u32::MAX),
                width: u32::try_from(i - start).unwrap_or(u32::MAX),
            });
        }
        match class(i) {
            SPACE | WORD => {}
            HASH => {
                // A comment: the rest of the line is skipped, whatever it holds.
                while !matches!(class(i), NEWLINE | END) {
                    i += 1;
                }
                break;
            }
            BEYOND_ASCII => {
                // A character beyond ASCII before any comment: columns count characters.
                let end = bytes[i..]
                    .iter()
                    .position(|&b| b == b'\n' || b == b'\r')
                    .map_or(bytes.len(), |n| i + n);
                tokenize_into(&rest[..end], tokens);
                return (end, line_ending(bytes, end));
            }
            _ => break,
        }
    }
    // A line starting with `//` is a comment as a whole (`//define shape ...` included).
    if tokens.first().is_some_and(|t| t.text.starts_with("//")) {
        tokens.clear();
    }
    (i, line_ending(bytes, i))
}

/// Classes of bytes for [`scan_line`].
const WORD: u8 = 0;
/// The whitespace of ASCII as `char::is_whitespace` knows it, but for line endings.
const SPACE: u8 = 1;
const NEWLINE: u8 = 2;
const HASH: u8 = 3;
const BEYOND_ASCII: u8 = 4;
/// Past the end of the text.
const END: u8 = 5;

const BYTE_CLASS: [u8; 256] = {
    let mut class = [WORD; 256];
    class[b' ' as usize] = SPACE;
    class[b'\t' as usize] = SPACE;
    class[0x0b] = SPACE;
    class[0x0c] = SPACE;
    class[b'\n' as usize] = NEWLINE;
    class[b'\r' as usize] = NEWLINE;
    class[b'#' as usize] = HASH;
    let mut b = 0x80;
    while b < 256 {
        class[b] = BEYOND_ASCII;
        b += 1;
    }
    class
};

const ONES: u64 = 0x0101_0101_0101_0101;
const HIGH_BITS: u64 = 0x8080_8080_8080_8080;

/// The high bit of each byte of `x` (eight bytes of text, the first in the lowest byte) whose
/// [`BYTE_CLASS`] is not `WORD`: ASCII whitespace (tab to carriage return, space), `#`, and
/// every byte beyond ASCII. Each test adds within a byte's low seven bits, which never carries
/// into the next byte.
fn non_word_bytes(x: u64) -> u64 {
    let low = x & !HIGH_BITS;
    let is = |c: u8| !((low ^ (ONES * u64::from(c))) + ONES * 0x7f) & HIGH_BITS;
    let from_tab = (low + ONES * (0x80 - 0x09)) & HIGH_BITS;
    let to_cr = !(low + ONES * (0x7f - 0x0d)) & HIGH_BITS;
    (x & HIGH_BITS) | is(b' ') | is(b'#') | (from_tab & to_cr)
}

/// The length of the line ending at byte `end`: CRLF, LF, a lone CR, or none at the end.
fn line_ending(bytes: &[u8], end: usize) -> usize {
    match (bytes.get(end), bytes.get(end + 1)) {
        (Some(b'\r'), Some(b'\n')) => 2,
        (Some(_), _) => 1,
        (None, _) => 0,
    }
}

/// The text of line `number` (from 1), without its line ending.
pub fn line_text(text: &str, number: u32) -> Option<&str> {
    let index = usize::try_from(number).ok()?.checked_sub(1)?;
    raw_lines(text).nth(index)
}

/// A fingerprint of what a scene file says apart from the names of its images: its tokens,
/// comments and spacing left out, with the file name of each render line replaced by its
/// extension (the format decides the bytes written). Two files of one folder with the same
/// key render the same images. `None` when a render line is not in the canonical form
/// `render <camera> <file> <width> <height> [<samples>]`: in the shorter variants, which token
/// names the image is settled only with the whole file read, and such files are never taken
/// for one another.
pub fn scene_key(text: &str) -> Option<u64> {
    let mut h = crate::util::Fnv64::default();
    let mut canonical = true;
    each_line(text, |line| {
        let tokens = &line.tokens;
        let is_render = tokens.first().is_some_and(|t| t.text == "render");
        let image_at = if is_render {
            canonical &= canonical_render_image(tokens).is_some();
            Some(2)
        } else {
            None
        };
        for (i, token) in tokens.iter().enumerate() {
            if Some(i) == image_at {
                let format = std::path::Path::new(token.text)
                    .extension()
                    .map(|e| e.to_string_lossy().to_ascii_lowercase());
                h.write_part(b"render-image");
                h.write_part(format.unwrap_or_default().as_bytes());
            } else {
                h.write_part(token.text.as_bytes());
            }
        }
        // Lines apart: `a b` then `c` is not `a` then `b c`.
        h.write(b"\n");
    });
    canonical.then(|| h.finish())
}

/// An image a render line names, and where.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ImageName {
    /// The file name as written.
    pub name: String,
    /// The line, counted from 1.
    pub line: u32,
    /// The column of the name, counted from 1 in characters.
    pub col: u32,
    /// The name's width in characters.
    pub width: u32,
    /// The whole line, for quoting.
    pub text: String,
}

/// The image each render line of a scene file names, where it names it. `None` when a render
/// line is not in the canonical form, as for [`scene_key`].
pub fn image_names(text: &str) -> Option<Vec<ImageName>> {
    let mut names = Vec::new();
    let mut canonical = true;
    each_line(text, |line| {
        let tokens = &line.tokens;
        if tokens.first().is_some_and(|t| t.text == "render") {
            match canonical_render_image(tokens) {
                Some(image) => names.push(ImageName {
                    name: image.text.to_string(),
                    line: line.number,
                    col: image.col,
                    width: image.width,
                    text: line.text.to_string(),
                }),
                None => canonical = false,
            }
        }
    });
    canonical.then_some(names)
}

/// The image token of a render line in the form `render <camera> <file> <width> <height>
/// [<samples>]`; `None` for the shorter variants.
fn canonical_render_image<'t, 'a>(tokens: &'t [Token<'a>]) -> Option<&'t Token<'a>> {
    let sized = tokens.len() >= 5 && looks_numeric(tokens[3].text) && looks_numeric(tokens[4].text);
    (sized && !looks_numeric(tokens[2].text)).then(|| &tokens[2])
}

/// The lines of a file without their line endings, without tokenizing them.
pub fn raw_lines(text: &str) -> impl Iterator<Item = &str> {
    let mut rest = text.strip_prefix('\u{feff}').unwrap_or(text);
    std::iter::from_fn(move || {
        if rest.is_empty() {
            // A final line ending does not start another line.
            return None;
        }
        let bytes = rest.as_bytes();
        match bytes.iter().position(|&b| b == b'\n' || b == b'\r') {
            None => {
                let line = rest;
                rest = "";
                Some(line)
            }
            Some(end) => {
                let line = &rest[..end];
                let skip = if bytes[end] == b'\r' && bytes.get(end + 1) == Some(&b'\n') {
                    2
                } else {
                    1
                };
                rest = &rest[end + skip..];
                Some(line)
            }
        }
    })
}

/// The 1-based number of the line at index `i`, saturating (a file cannot have 4 billion
/// lines under the input limit, but the arithmetic must not wrap if it had).
fn line_number(i: usize) -> u32 {
    u32::try_from(i).map_or(u32::MAX, |n| n.saturating_add(1))
}

/// The tokens on a line, when they are more than [`crate::limits::MAX_TOKENS_PER_LINE`].
pub fn overlong(raw: &str) -> Option<usize> {
    // Only long lines can hold that many tokens; counting is skipped for the rest.
    if raw.len() < crate::limits::MAX_TOKENS_PER_LINE {
        return None;
    }
    let code = raw.split('#').next().unwrap_or("");
    let count = code.split_whitespace().count();
    (count > crate::limits::MAX_TOKENS_PER_LINE).then_some(count)
}

/// Lines holding more than [`crate::limits::MAX_TOKENS_PER_LINE`] tokens: (line number,
/// tokens on it).
#[cfg(test)]
pub fn overlong_lines(text: &str) -> Vec<(u32, usize)> {
    raw_lines(text)
        .enumerate()
        .filter_map(|(i, raw)| Some((line_number(i), overlong(raw)?)))
        .collect()
}

/// The tokens of one line, comments removed.
pub fn tokenize(line: &str) -> Vec<Token<'_>> {
    let mut tokens = Vec::new();
    tokenize_into(line, &mut tokens);
    tokens
}

/// The tokens of one line, comments removed, into `tokens` (cleared first).
pub fn tokenize_into<'t>(line: &'t str, tokens: &mut Vec<Token<'t>>) {
    tokens.clear();
    if line.is_ascii() {
        tokenize_ascii(line, tokens);
    } else {
        tokenize_chars(line, tokens);
    }
    // A line starting with `//` is a comment as a whole (`//define shape ...` included).
    if tokens.first().is_some_and(|t| t.text.starts_with("//")) {
        tokens.clear();
    }
}

/// [`tokenize_into`] for a line of ASCII, where a character is a byte: the common case, read
/// without decoding characters.
fn tokenize_ascii<'t>(line: &'t str, tokens: &mut Vec<Token<'t>>) {
    let bytes = line.as_bytes();
    let code = bytes.iter().position(|&b| b == b'#').unwrap_or(bytes.len());
    let mut i = 0;
    while i < code {
        // The whitespace of ASCII as `char::is_whitespace` knows it.
        while i < code && matches!(bytes[i], b' ' | b'\t' | b'\n' | 0x0b | 0x0c | b'\r') {
            i += 1;
        }
        if i == code {
            break;
        }
        let start = i;
        while i < code && !matches!(bytes[i], b' ' | b'\t' | b'\n' | 0x0b | 0x0c | b'\r') {
            i += 1;
        }
        if tokens.len() >= crate::limits::MAX_TOKENS_PER_LINE {
            // The rest is not kept (see `overlong_lines`, which reports the line).
            return;
        }
        tokens.push(Token {
            text: &line[start..i],
            col: u32::try_from(start + 1).unwrap_or(u32::MAX),
            width: u32::try_from(i - start).unwrap_or(u32::MAX),
        });
    }
}

/// [`tokenize_into`] for any line: columns and widths count characters.
fn tokenize_chars<'t>(line: &'t str, tokens: &mut Vec<Token<'t>>) {
    let mut start: Option<(usize, u32)> = None;
    let mut col: u32 = 0;
    let mut end_byte = line.len();
    for (i, ch) in line.char_indices() {
        col = col.saturating_add(1);
        if ch == '#' {
            end_byte = i;
            break;
        }
        if ch.is_whitespace() {
            if let Some((s, c)) = start.take() {
                tokens.push(make_token(line, s, i, c));
                if tokens.len() >= crate::limits::MAX_TOKENS_PER_LINE {
                    // The rest is not kept (see `overlong_lines`, which reports the line).
                    return;
                }
            }
        } else if start.is_none() {
            start = Some((i, col));
        }
    }
    if let Some((s, c)) = start {
        tokens.push(make_token(line, s, end_byte, c));
    }
}

fn make_token(line: &str, start: usize, end: usize, col: u32) -> Token<'_> {
    let text = &line[start..end];
    Token {
        text,
        col,
        width: u32::try_from(text.chars().count()).unwrap_or(u32::MAX),
    }
}

/// Why a token is not an acceptable number.
#[derive(Clone, Debug, PartialEq)]
pub enum NumberError {
    /// Not a number at all (`1O`, `abc`, `0x10`).
    Malformed,
    /// `nan`, `inf`, `infinity`: never accepted.
    NotFinite,
    /// A C-style suffix such as `1.0f`; carries the number without it.
    Suffix(String),
    /// A decimal comma (`1,5`); carries the number written with a point.
    DecimalComma(String),
    /// Finite but absurdly large (or overflowing to infinity, like `1e999`).
    TooLarge,
}

/// Reads a finite decimal number: `1`, `-1.5`, `.5`, `-.5`, `+100`, `1e-3`, `1.`.
pub fn parse_number(s: &str) -> Result<f64, NumberError> {
    if let Some(v) = short_decimal(s) {
        return Ok(v);
    }
    if is_decimal(s) {
        let v: f64 = s.parse().map_err(|_| NumberError::Malformed)?;
        if !v.is_finite() || v.abs() > MAX_MAGNITUDE {
            return Err(NumberError::TooLarge);
        }
        return Ok(v);
    }
    let lower = s.to_ascii_lowercase();
    let unsigned = lower.trim_start_matches(['+', '-']);
    if matches!(unsigned, "nan" | "inf" | "infinity") {
        return Err(NumberError::NotFinite);
    }
    if let Some(stem) = s.strip_suffix(['f', 'F', 'd', 'D']) {
        if is_decimal(stem) {
            return Err(NumberError::Suffix(stem.to_string()));
        }
    }
    if s.matches(',').count() == 1 {
        let dotted = s.replace(',', ".");
        if is_decimal(&dotted) {
            return Err(NumberError::DecimalComma(dotted));
        }
    }
    Err(NumberError::Malformed)
}

/// Powers of ten exactly representable as `f64`.
const EXACT_POWERS_OF_TEN: [f64; 16] = [
    1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15,
];

/// The common number without exponent and with at most 15 digits (`-12.3456`), read in one
/// pass: its digits as an integer (exact, below 2^53) over a power of ten (exact), one
/// correctly rounded division, so the same value as `str::parse` gives. `None` for anything
/// else (read by the general path) and for magnitudes beyond [`MAX_MAGNITUDE`].
fn short_decimal(s: &str) -> Option<f64> {
    let b = s.as_bytes();
    let (negative, digits) = match b.first()? {
        b'-' => (true, &b[1..]),
        b'+' => (false, &b[1..]),
        _ => (false, b),
    };
    // At most 15 digits and a point.
    if digits.len() > 16 {
        return None;
    }
    let mut mantissa: u64 = 0;
    let mut point: Option<usize> = None;
    for (k, &c) in digits.iter().enumerate() {
        let d = c.wrapping_sub(b'0');
        if d < 10 {
            mantissa = mantissa * 10 + u64::from(d);
        } else if c == b'.' && point.is_none() {
            point = Some(k);
        } else {
            return None;
        }
    }
    let count = digits.len() - usize::from(point.is_some());
    if count == 0 || count > 15 {
        return None;
    }
    let fraction = point.map_or(0, |p| digits.len() - 1 - p);
    let v = mantissa as f64 / EXACT_POWERS_OF_TEN[fraction];
    if v > MAX_MAGNITUDE {
        return None;
    }
    Some(if negative { -v } else { v })
}

/// Whether `s` has the shape of a decimal number (checked before calling `str::parse`, which
/// would also accept `inf` and `nan`).
fn is_decimal(s: &str) -> bool {
    let b = s.as_bytes();
    let mut i = 0;
    if i < b.len() && (b[i] == b'+' || b[i] == b'-') {
        i += 1;
    }
    let int_start = i;
    while i < b.len() && b[i].is_ascii_digit() {
        i += 1;
    }
    let mut digits = i - int_start;
    if i < b.len() && b[i] == b'.' {
        i += 1;
        let frac_start = i;
        while i < b.len() && b[i].is_ascii_digit() {
            i += 1;
        }
        digits += i - frac_start;
    }
    if digits == 0 {
        return false;
    }
    if i < b.len() && (b[i] == b'e' || b[i] == b'E') {
        i += 1;
        if i < b.len() && (b[i] == b'+' || b[i] == b'-') {
            i += 1;
        }
        let exp_start = i;
        while i < b.len() && b[i].is_ascii_digit() {
            i += 1;
        }
        if i == exp_start {
            return false;
        }
    }
    i == b.len()
}

/// Whether a token was probably meant as a number (even a malformed one such as `1O` or
/// `nan`). Used to tell layouts apart, e.g. a material name written before the coordinates.
pub fn looks_numeric(s: &str) -> bool {
    let unsigned = s.trim_start_matches(['+', '-']);
    if ["nan", "inf", "infinity"]
        .iter()
        .any(|w| unsigned.eq_ignore_ascii_case(w))
    {
        return true;
    }
    let mut chars = unsigned.chars();
    match chars.next() {
        Some(c) if c.is_ascii_digit() => true,
        Some('.') => chars.next().is_some_and(|c| c.is_ascii_digit()),
        _ => false,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scene_keys_see_the_scene_and_the_image_format_only() {
        let frame = |comment: &str, image: &str| {
            format!("# {comment}\ndefine shape sphere s 0 0 0 1 m\n  render eye {image} 32 24\n")
        };
        let key = |t: &str| scene_key(t).expect("canonical render lines");
        let a = key(&frame("frame 1", "frame_1.png"));
        assert_eq!(a, key(&frame("frame 2 of 9", "out/frame_2.PNG")));
        assert_ne!(a, key(&frame("frame 1", "frame_1.ppm")));
        assert_ne!(
            a,
            key(&frame("frame 1", "frame_1.png").replace("32 24", "32 25"))
        );
        assert_ne!(
            a,
            key(&frame("frame 1", "frame_1.png").replace("s 0 0 0", "s 0 0 0.5"))
        );
        // Tokens split across lines differently are different statements.
        assert_ne!(key("a b\nc\n"), key("a\nb c\n"));
        // The short variants name their image only once the whole file is read.
        assert_eq!(scene_key("render eye frame.png\n"), None);
        assert_eq!(scene_key("render frame.png 32 24\n"), None);
    }

    #[test]
    fn accepts_every_documented_number_form() {
        for (text, value) in [
            ("1", 1.0),
            ("-1.5", -1.5),
            (".5", 0.5),
            ("-.5", -0.5),
            ("+100", 100.0),
            ("1e-3", 0.001),
            ("2E+2", 200.0),
            ("1.", 1.0),
            ("000", 0.0),
        ] {
            assert_eq!(parse_number(text), Ok(value), "{text}");
        }
    }

    #[test]
    fn short_decimals_read_as_the_standard_library_reads_them() {
        let mut rng = crate::util::SplitMix64::new(0x2545_F491_4F6C_DD1D);
        let mut next = move || rng.next_u64();
        for _ in 0..200_000 {
            let r = next();
            let int = (r >> 20) % 10u64.pow((r % 9) as u32 + 1);
            let frac_digits = ((r >> 8) % 9) as usize;
            let frac = next() % 10u64.pow(frac_digits as u32);
            let sign = ["", "-", "+"][(r % 3) as usize];
            let text = match (r >> 4) % 4 {
                0 => format!("{sign}{int}"),
                1 => format!("{sign}.{frac:0frac_digits$}"),
                2 => format!("{sign}{int}."),
                _ => format!("{sign}{int}.{frac:0frac_digits$}"),
            };
            let expected: f64 = text.parse().unwrap_or_else(|_| panic!("{text}"));
            let got = parse_number(&text);
            if text.trim_start_matches(['+', '-']) == "." {
                assert_eq!(got, Err(NumberError::Malformed), "{text}");
            } else {
                assert_eq!(got.map(f64::to_bits), Ok(expected.to_bits()), "{text}");
            }
        }
        for (text, value) in [
            ("-0", -0.0f64),
            ("0.1", 0.1),
            ("999999999999", 999999999999.0),
            ("123456789012.345", 123456789012.345),
            ("0.000000000000001", 1e-15),
        ] {
            let got = parse_number(text);
            assert!(got.is_ok() || value.abs() > MAX_MAGNITUDE, "{text}");
            if let Ok(v) = got {
                assert_eq!(v.to_bits(), value.to_bits(), "{text}");
            }
        }
        assert_eq!(parse_number("1000000000001"), Err(NumberError::TooLarge));
        assert_eq!(parse_number("1.2.3"), Err(NumberError::Malformed));
    }

    #[test]
    fn rejects_non_finite_and_malformed_numbers() {
        assert_eq!(parse_number("1O"), Err(NumberError::Malformed));
        assert_eq!(parse_number("nan"), Err(NumberError::NotFinite));
        assert_eq!(parse_number("-inf"), Err(NumberError::NotFinite));
        assert_eq!(parse_number("Infinity"), Err(NumberError::NotFinite));
        assert_eq!(parse_number("0x10"), Err(NumberError::Malformed));
        assert_eq!(parse_number("1e"), Err(NumberError::Malformed));
        assert_eq!(parse_number("."), Err(NumberError::Malformed));
        assert_eq!(parse_number("-"), Err(NumberError::Malformed));
        assert_eq!(parse_number("1e999"), Err(NumberError::TooLarge));
        assert_eq!(parse_number("1e13"), Err(NumberError::TooLarge));
        assert_eq!(
            parse_number("1.0f"),
            Err(NumberError::Suffix("1.0".to_string()))
        );
        assert_eq!(
            parse_number("1,5"),
            Err(NumberError::DecimalComma("1.5".to_string()))
        );
    }

    #[test]
    fn numeric_looking_tokens() {
        for t in ["1", "-1", ".5", "-.5", "1O", "nan", "-inf", "+3"] {
            assert!(looks_numeric(t), "{t}");
        }
        for t in ["red", "image.ppm", ".ppm", ".", "x1", "-"] {
            assert!(!looks_numeric(t), "{t}");
        }
    }

    #[test]
    fn tokens_carry_character_columns_and_comments_are_dropped() {
        let toks = tokenize("  jklö\t12 # comment 3");
        assert_eq!(
            toks,
            vec![
                Token {
                    text: "jklö",
                    col: 3,
                    width: 4
                },
                Token {
                    text: "12",
                    col: 8,
                    width: 2
                },
            ]
        );
        assert!(tokenize("// define shape").is_empty());
        assert!(tokenize("   //define shape").is_empty());
        assert_eq!(tokenize("a#b").len(), 1);
    }

    #[test]
    fn ascii_and_character_tokenizers_agree() {
        for line in [
            "define shape sphere s 0 0 -5 1 red",
            "  a\tb\x0bc\x0cd  # e f",
            "x#y",
            "",
            "   ",
            "// comment",
            "#",
            "a  b ",
        ] {
            let mut ascii = Vec::new();
            tokenize_ascii(line, &mut ascii);
            let mut chars = Vec::new();
            tokenize_chars(line, &mut chars);
            assert_eq!(ascii, chars, "{line:?}");
        }
    }

    #[test]
    fn each_line_sees_what_lines_splits() {
        for text in [
            "a # jklö\n  b\u{a0}c d\n\u{a0}x // y\n//z w\n  // v\n#\n\n\r\n\r",
            "x\ty\x0bz\x0c\n\u{feff}q",
            "\u{feff}",
            "a",
        ] {
            let mut seen = Vec::new();
            each_line(text, |l| seen.push((l.number, l.text, l.tokens.clone())));
            let expected: Vec<_> = lines(text)
                .into_iter()
                .map(|l| (l.number, l.text, l.tokens))
                .collect();
            assert_eq!(seen, expected, "{text:?}");
        }
        let text = "\u{feff}a b\r\nc\r\n\r\nd # x\rjklö 1";
        let mut seen = Vec::new();
        each_line(text, |l| seen.push((l.number, l.text, l.tokens.clone())));
        let expected: Vec<_> = lines(text)
            .into_iter()
            .map(|l| (l.number, l.text, l.tokens))
            .collect();
        assert_eq!(seen, expected);
        assert_eq!(line_text(text, 4), Some("d # x"));
        assert_eq!(line_text(text, 9), None);
        assert_eq!(line_text(text, 0), None);
    }

    #[test]
    fn eight_bytes_at_a_time_classify_as_the_table_does() {
        for b in 0..=255u8 {
            for at in 0..8 {
                // The byte among others of every class, before and after it.
                let mut chunk = [b'a'; 8];
                chunk[at] = b;
                chunk[(at + 3) % 8] = [b' ', 0xc3, b'#', b'\n', b'x'][usize::from(b) % 5];
                let got = non_word_bytes(u64::from_le_bytes(chunk));
                let want = chunk.iter().enumerate().fold(0u64, |m, (k, &c)| {
                    m | (u64::from(BYTE_CLASS[usize::from(c)] != WORD) << (8 * k + 7))
                });
                assert_eq!(got, want, "{chunk:?}");
            }
        }
    }

    #[test]
    fn each_line_splits_random_text_as_lines_does() {
        let pieces = [
            "a",
            "define",
            "1.5",
            " ",
            "  ",
            "\t",
            "\x0b",
            "\x0c",
            "\n",
            "\r",
            "\r\n",
            "#",
            "//",
            "jklö",
            "\u{a0}",
            "\u{1}",
            "\x7f",
            "é",
            "sphere_name_long",
        ];
        let mut rng = crate::util::SplitMix64::new(0x2545_F491_4F6C_DD1D);
        for _ in 0..3000 {
            let mut text = String::new();
            for _ in 0..rng.below(40) {
                text.push_str(pieces[rng.below(pieces.len())]);
            }
            let mut seen = Vec::new();
            each_line(&text, |l| seen.push((l.number, l.text, l.tokens.clone())));
            let expected: Vec<_> = lines(&text)
                .into_iter()
                .map(|l| (l.number, l.text, l.tokens))
                .collect();
            assert_eq!(seen, expected, "{text:?}");
        }
    }

    #[test]
    fn crlf_missing_final_newline_and_bom() {
        let ls = lines("\u{feff}a b\r\nc\r\n\r\nd");
        assert_eq!(ls.len(), 4);
        assert_eq!(ls[0].text, "a b");
        assert_eq!(ls[1].number, 2);
        assert!(ls[2].tokens.is_empty());
        assert_eq!(ls[3].tokens[0].text, "d");
        assert_eq!(lines("a\n").len(), 1);
        assert!(lines("").is_empty());
    }

    #[test]
    fn a_lone_cr_ends_a_line() {
        let ls = lines("// comment\rdefine x\r\rrender c\r");
        assert_eq!(ls.len(), 4);
        assert!(ls[0].tokens.is_empty());
        assert_eq!(ls[1].tokens[0].text, "define");
        assert_eq!(ls[3].number, 4);
        assert_eq!(lines("a\r\nb\rc\n").len(), 3);
        assert_eq!(lines("a\r\r\nb").len(), 3);
        assert_eq!(lines("\r").len(), 1);
    }

    #[test]
    fn tokens_of_one_line_are_capped_and_the_line_reported() {
        let text = format!(
            "a\n{}\n",
            "x ".repeat(crate::limits::MAX_TOKENS_PER_LINE + 3)
        );
        let ls = lines(&text);
        assert_eq!(ls[1].tokens.len(), crate::limits::MAX_TOKENS_PER_LINE);
        assert_eq!(
            overlong_lines(&text),
            vec![(2, crate::limits::MAX_TOKENS_PER_LINE + 3)]
        );
        assert!(overlong_lines("a b c\n").is_empty());
    }
}
