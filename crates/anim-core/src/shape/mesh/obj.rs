//! Reading a mesh from a Wavefront OBJ file with the `tobj` crate.
//!
//! `tobj` reports what went wrong but not where, so a light pass over the text comes first:
//! it checks every line `tobj` would read (numbers of `v`, `vt` and `vn` lines, the indices
//! of `f` and `l` lines, `usemtl` names) by the same rules, and points at the file's own line
//! and column. Only a file that passes reaches `tobj`, whose model is turned into the mesh's
//! compact arrays and dropped before the hierarchy is built (the peak holds one copy).

use super::{Mesh, MeshError};
use crate::diag::{Diagnostic, Loc, Severity};
use crate::limits::{MAX_MESH_TRIANGLES, MAX_OBJ_LINE_BYTES};
use crate::util::human_bytes;
use glam::Vec3;
use std::fs::File;
use std::io::{BufRead, BufReader, Read, Seek as _};
use std::path::Path;
use std::sync::Arc;

/// Loads the mesh of the OBJ file at `path`, a file the user names (a scene's meshes are
/// opened confined, by the scene builder, and read by [`load_open`]), within the default
/// memory budget. What is not a regular file (a pipe would wait for a writer, a device could
/// feed a line without end) is refused unread.
pub fn load(path: &Path, max_input: u64) -> Result<Mesh, Box<Diagnostic>> {
    let opened = crate::input::open_named(path, path, true).map_err(|refusal| {
        let why = match refusal {
            crate::input::Refusal::Io(e) => e.to_string(),
            _ => "it is not a regular file".to_string(),
        };
        Box::new(Diagnostic::file_error(
            path,
            format!("cannot be read: {why}"),
        ))
    })?;
    let budget = crate::limits::default_memory_budget();
    load_open(opened.file(), path, max_input, budget)
}

/// Loads the mesh of the open OBJ file `file`, named `path` in messages: every reading of it
/// (the check, `tobj`, a line quoted again) is of this one open file. A problem on a line
/// points at the OBJ file's own line and column; a problem with the whole file (it cannot
/// be read, it holds no triangles, it would need more than `max_memory` bytes to read and
/// build: `limits::mesh_memory`) has no location and a message that follows the file's name
/// ("… holds no triangles").
pub fn load_open(
    file: &File,
    path: &Path,
    max_input: u64,
    max_memory: u64,
) -> Result<Mesh, Box<Diagnostic>> {
    let cannot = |e: String| Box::new(Diagnostic::file_error(path, format!("cannot be read: {e}")));
    let meta = file.metadata().map_err(|e| cannot(e.to_string()))?;
    if !meta.is_file() {
        return Err(cannot("it is not a regular file".to_string()));
    }
    if meta.len() > max_input {
        let size = format!("{} bytes", meta.len());
        return Err(Box::new(Diagnostic::too_large(path, &size, max_input)));
    }
    let open =
        || -> Result<_, Box<Diagnostic>> { obj_lines(file).map_err(|e| cannot(e.to_string())) };
    let scan = scan(open()?).map_err(|problem| Box::new(problem.diagnostic(path, file)))?;
    if scan.triangles == 0 {
        return Err(Box::new(Diagnostic::file_error(
            path,
            MeshError::NoTriangles.to_string(),
        )));
    }
    // Counted by the pass, refused before the reading that costs the memory.
    let needed = crate::limits::mesh_memory(scan.vertices_bound(), scan.triangles as u64);
    if needed > max_memory {
        let message = format!(
            "needs about {} of memory to read and build its {} triangles, more than the {} allowed",
            human_bytes(needed),
            scan.triangles,
            human_bytes(max_memory)
        );
        return Err(Box::new(
            Diagnostic::file_error(path, message).with_help(crate::limits::RAISE_MEMORY),
        ));
    }
    let options = tobj::LoadOptions {
        triangulate: true,
        single_index: true,
        ignore_points: true,
        ignore_lines: true,
    };
    // Materials are the scene file's business: `mtllib` lines are not followed.
    let loaded = tobj::load_obj_buf(&mut open()?, &options, |_| {
        Err(tobj::LoadError::OpenFileFailed)
    });
    let (models, _) = loaded.map_err(|e| {
        Box::new(Diagnostic::file_error(
            path,
            format!("cannot be read as OBJ: {e}"),
        ))
    })?;

    let mut positions: Vec<Vec3> = Vec::with_capacity(scan.vertices_hint());
    let mut normals: Vec<Vec3> = Vec::new();
    let mut triangles: Vec<[u32; 3]> = Vec::with_capacity(scan.triangles);
    let mut smooth = true;
    for model in models {
        // Each model is dropped as soon as it is copied.
        let m = model.mesh;
        let base = positions.len() as u32;
        let vec3s = |v: &[f32]| {
            v.chunks_exact(3)
                .map(|c| Vec3::new(c[0], c[1], c[2]))
                .collect::<Vec<_>>()
        };
        smooth &= m.normals.len() == m.positions.len();
        if smooth {
            normals.extend(vec3s(&m.normals));
        }
        positions.extend(vec3s(&m.positions));
        triangles.extend(
            m.indices
                .chunks_exact(3)
                .map(|t| [t[0] + base, t[1] + base, t[2] + base]),
        );
    }
    if !smooth {
        normals = Vec::new();
    }
    positions.shrink_to_fit();
    normals.shrink_to_fit();
    Mesh::new(positions, normals, triangles)
        .map_err(|e| Box::new(Diagnostic::file_error(path, e.to_string())))
}

/// An OBJ file's text as both readers of it see it: a UTF-8 byte order mark dropped, every
/// line ending (LF, CRLF or a lone CR, as old Mac files end their lines) written as LF, so that
/// line numbers are an editor's, and polyline (`l`) lines turned into comments: `tobj` would
/// read a polyline of three or more points as a face, and a polyline draws nothing.
struct ObjLines<R> {
    text: R,
    line: Vec<u8>,
    served: usize,
    at_start: bool,
    /// The last line ended in CR at the end of a buffer: an LF next is part of that ending.
    after_cr: bool,
}

impl<R: BufRead> ObjLines<R> {
    fn new(text: R) -> Self {
        ObjLines {
            text,
            line: Vec::new(),
            served: 0,
            at_start: true,
            after_cr: false,
        }
    }

    /// Reads the next line into `line`; false at the end of the text.
    fn next_line(&mut self) -> std::io::Result<bool> {
        self.line.clear();
        self.served = 0;
        loop {
            let buf = self.text.fill_buf()?;
            if buf.is_empty() {
                // A last line without its line ending.
                if self.line.is_empty() {
                    return Ok(false);
                }
                self.finish_line();
                return Ok(true);
            }
            let start = usize::from(std::mem::take(&mut self.after_cr) && buf[0] == b'\n');
            let found = buf[start..].iter().position(|&b| b == b'\n' || b == b'\r');
            let end = found.map_or(buf.len(), |i| start + i);
            if self.line.len() + (end - start) > MAX_OBJ_LINE_BYTES {
                return Err(invalid(format!(
                    "a line is longer than {MAX_OBJ_LINE_BYTES} bytes"
                )));
            }
            if buf[start..end].contains(&0) {
                return Err(invalid("not a text file (it holds NUL bytes)".to_string()));
            }
            self.line.extend_from_slice(&buf[start..end]);
            if found.is_none() {
                let n = buf.len();
                self.text.consume(n);
                continue;
            }
            let mut consumed = end + 1;
            if buf[end] == b'\r' {
                match buf.get(consumed) {
                    Some(b'\n') => consumed += 1,
                    Some(_) => {}
                    None => self.after_cr = true,
                }
            }
            self.text.consume(consumed);
            self.finish_line();
            return Ok(true);
        }
    }

    /// Drops the byte order mark of the first line, comments out a polyline, and ends the
    /// line with LF.
    fn finish_line(&mut self) {
        if std::mem::take(&mut self.at_start) && self.line.starts_with(b"\xef\xbb\xbf") {
            self.line.drain(..3);
        }
        self.comment_out_polyline();
        self.line.push(b'\n');
    }

    fn comment_out_polyline(&mut self) {
        if let Some(at) = self.line.iter().position(|b| !b.is_ascii_whitespace()) {
            let next = self.line.get(at + 1).copied();
            if self.line[at] == b'l' && next.is_none_or(|b| b.is_ascii_whitespace()) {
                self.line[at] = b'#';
            }
        }
    }
}

impl<R: BufRead> Read for ObjLines<R> {
    fn read(&mut self, out: &mut [u8]) -> std::io::Result<usize> {
        let line = self.fill_buf()?;
        let n = out.len().min(line.len());
        out[..n].copy_from_slice(&line[..n]);
        self.consume(n);
        Ok(n)
    }
}

/// Lines are served from the line just read, with no second buffer in between.
impl<R: BufRead> BufRead for ObjLines<R> {
    fn fill_buf(&mut self) -> std::io::Result<&[u8]> {
        if self.served == self.line.len() && !self.next_line()? {
            return Ok(&[]);
        }
        Ok(&self.line[self.served..])
    }

    fn consume(&mut self, amount: usize) {
        self.served = (self.served + amount).min(self.line.len());
    }
}

/// A reading error of the text itself, which the scan reports at the line it is on.
fn invalid(message: String) -> std::io::Error {
    std::io::Error::new(std::io::ErrorKind::InvalidData, message)
}

/// The lines of an OBJ file, as [`ObjLines`] gives them.
/// The lines of `file` from its start.
fn obj_lines(mut file: &File) -> std::io::Result<ObjLines<BufReader<&File>>> {
    file.rewind()?;
    Ok(ObjLines::new(BufReader::new(file)))
}

/// A problem found on one line: byte range of the culprit and the message.
#[derive(Debug)]
struct Problem {
    line: u64,
    start: usize,
    end: usize,
    message: String,
    /// The line's text, when the pass still had it (problems found at the end of the file
    /// read it again).
    text: Option<String>,
}

impl Problem {
    fn diagnostic(self, path: &Path, file: &File) -> Diagnostic {
        let text = self.text.or_else(|| nth_line(file, self.line));
        let text = text.unwrap_or_default();
        let start = self.start.min(text.len());
        let col = text[..start].chars().count() + 1;
        let width = text
            .get(start..self.end.min(text.len()))
            .map_or(1, |t| t.chars().count());
        let loc = Loc {
            file: Arc::from(path),
            line: u32::try_from(self.line).unwrap_or(u32::MAX),
            col: u32::try_from(col).unwrap_or(u32::MAX),
        };
        Diagnostic::new(Severity::Error, loc, self.message)
            .with_source(&text, u32::try_from(width).unwrap_or(u32::MAX))
    }
}

/// The text of line `n` (from 1) of `file`, read again for a problem found after the line had
/// passed.
fn nth_line(file: &File, n: u64) -> Option<String> {
    let mut reader = obj_lines(file).ok()?;
    let mut buf = Vec::new();
    for _ in 0..n {
        buf.clear();
        if reader.read_until(b'\n', &mut buf).ok()? == 0 {
            return None;
        }
    }
    Some(String::from_utf8_lossy(trim_line_end(&buf)).into_owned())
}

fn trim_line_end(buf: &[u8]) -> &[u8] {
    let buf = buf.strip_suffix(b"\n").unwrap_or(buf);
    buf.strip_suffix(b"\r").unwrap_or(buf)
}

/// Indexed element kinds of a face vertex `v/vt/vn`.
const KINDS: [&str; 3] = ["vertex", "texture coordinate", "normal"];

/// The largest index a face names of one kind, and where.
#[derive(Clone, Copy, Debug, Default)]
struct Farthest {
    index: u64,
    line: u64,
    start: usize,
    end: usize,
}

/// What the pass counted.
#[derive(Debug, Default)]
struct Scan {
    /// Positions, texture coordinates and normals defined.
    counts: [u64; 3],
    triangles: usize,
    farthest: [Farthest; 3],
    /// The first relative index of each kind met before the file defined any of that kind:
    /// harmless if it never does (`tobj` ignores the kind), else it reaches before the first.
    early: [Option<Farthest>; 3],
}

impl Scan {
    fn vertices_hint(&self) -> usize {
        usize::try_from(self.counts[0]).unwrap_or(0)
    }

    /// The vertices the mesh is built with, as the file's elements count them: the reader
    /// makes one for each pairing of a position with a texture coordinate and a normal, as
    /// many as the most numerous of the three in a file that pairs them one to one.
    fn vertices_bound(&self) -> u64 {
        self.counts.iter().copied().max().unwrap_or(0)
    }
}

/// Whitespace-separated words of a line with their byte offsets (Unicode whitespace, as
/// `tobj` splits them).
fn words(line: &str) -> impl Iterator<Item = (usize, &str)> {
    line.split_whitespace()
        .map(move |w| (w.as_ptr() as usize - line.as_ptr() as usize, w))
}

fn scan(mut reader: impl BufRead) -> Result<Scan, Problem> {
    let mut s = Scan::default();
    let mut buf = Vec::new();
    let mut line_no = 0u64;
    loop {
        buf.clear();
        let read = reader.read_until(b'\n', &mut buf).map_err(|e| Problem {
            line: line_no + 1,
            start: 0,
            end: 0,
            message: format!("cannot be read: {e}"),
            text: Some(String::new()),
        })?;
        if read == 0 {
            break;
        }
        line_no += 1;
        let bytes = trim_line_end(&buf);
        let Ok(line) = std::str::from_utf8(bytes) else {
            let good = std::str::from_utf8(bytes).map_or_else(|e| e.valid_up_to(), |_| 0);
            return Err(Problem {
                line: line_no,
                start: good,
                end: good + 1,
                message: "not UTF-8 text (an OBJ file is text)".to_string(),
                text: Some(String::from_utf8_lossy(bytes).into_owned()),
            });
        };
        let at = |start: usize, end: usize, message: String| Problem {
            line: line_no,
            start,
            end,
            message,
            text: Some(line.to_string()),
        };
        scan_line(&mut s, line, line_no)
            .map_err(|(start, end, message)| at(start, end, message))?;
    }
    for (kind, early) in s.early.iter().enumerate() {
        if let Some(early) = early.as_ref().filter(|_| s.counts[kind] > 0) {
            return Err(Problem {
                line: early.line,
                start: early.start,
                end: early.end,
                message: format!(
                    "relative {} index -{} reaches before the first one (0 defined so far)",
                    KINDS[kind], early.index
                ),
                text: None,
            });
        }
    }
    for (kind, far) in s.farthest.iter().enumerate() {
        // Every index must name something the file defines: `tobj` ignores indices of kinds
        // a file defines none of, but such a face says the file is not what its author meant.
        let defined = s.counts[kind];
        if far.index > defined {
            return Err(Problem {
                line: far.line,
                start: far.start,
                end: far.end,
                message: format!(
                    "face refers to {} {} but the file defines {defined}",
                    KINDS[kind], far.index
                ),
                text: None,
            });
        }
    }
    Ok(s)
}

type LineProblem = (usize, usize, String);

/// Checks one line as `tobj` reads it, counting what it defines.
fn scan_line(s: &mut Scan, line: &str, line_no: u64) -> Result<(), LineProblem> {
    let mut ws = words(line);
    let Some((_, keyword)) = ws.next() else {
        return Ok(());
    };
    let end = line.len();
    match keyword {
        "v" => {
            vertex(ws, end)?;
            s.counts[0] += 1;
        }
        "vt" => {
            for what in [
                "the texture coordinate u (a number)",
                "the texture coordinate v (a number)",
            ] {
                number(ws.next(), what, end)?;
            }
            s.counts[1] += 1;
        }
        "vn" => {
            for what in [
                "the normal's x component (a number)",
                "the normal's y component (a number)",
                "the normal's z component (a number)",
            ] {
                let w = ws.next();
                let v = number(w, what, end)?;
                if !v.is_finite() {
                    let (a, t) = w.unwrap_or((end, ""));
                    return Err((a, a + t.len(), "normal is not a finite number".to_string()));
                }
            }
            s.counts[2] += 1;
        }
        // Polylines (`l`) never get here: they reach both readers as comments (`ObjLines`).
        "f" => {
            let mut corners = 0usize;
            for (at, word) in ws {
                face_vertex(s, at, word, line_no)?;
                corners += 1;
            }
            if corners >= 3 {
                s.triangles += corners - 2;
                if s.triangles > MAX_MESH_TRIANGLES {
                    return Err((
                        0,
                        end,
                        format!("a mesh may hold at most {MAX_MESH_TRIANGLES} triangles"),
                    ));
                }
            }
        }
        "usemtl" if ws.next().is_none() => {
            return Err((
                end,
                end,
                "expected a material name, found end of line".into(),
            ));
        }
        _ => {}
    }
    Ok(())
}

/// The number of word `w` (`None` past the last word of a line `end` bytes long), or what
/// the line should have had there.
#[inline(always)]
fn number(w: Option<(usize, &str)>, what: &str, end: usize) -> Result<f32, LineProblem> {
    match w {
        None => Err((end, end, format!("expected {what}, found end of line"))),
        Some((at, text)) => text.parse::<f32>().map_err(|_| {
            (
                at,
                at + text.len(),
                format!("expected {what}, found '{text}'"),
            )
        }),
    }
}

/// Checks the words `ws` after a `v` of a line `end` bytes long: x y z, then a weight w or an
/// r g b colour, as `tobj` reads them.
#[inline(always)]
fn vertex<'a>(
    mut ws: impl Iterator<Item = (usize, &'a str)>,
    end: usize,
) -> Result<(), LineProblem> {
    let mut xyz = [0.0f32; 3];
    let mut spans = [(0usize, 0usize); 3];
    // Written out, not formatted: this runs three times on each of a mesh's vertices.
    let whats = [
        "the vertex's x coordinate (a number)",
        "the vertex's y coordinate (a number)",
        "the vertex's z coordinate (a number)",
    ];
    for (i, what) in whats.into_iter().enumerate() {
        let w = ws.next();
        xyz[i] = number(w, what, end)?;
        spans[i] = w.map_or((end, end), |(a, t)| (a, a + t.len()));
    }
    let rest: Vec<(usize, &str)> = ws.collect();
    match rest.len() {
        0 | 3 => {}
        1 => {
            let w = number(Some(rest[0]), "the vertex's weight w (a number)", end)?;
            let (a, t) = rest[0];
            if w == 0.0 {
                return Err((a, a + t.len(), "vertex weight w is 0".to_string()));
            }
            for c in &mut xyz {
                *c /= w;
            }
        }
        n => {
            let (a, _) = rest[0];
            return Err((
                a,
                end,
                format!(
                    "a vertex takes x y z and then a weight w or an r g b colour; \
                     found {n} more words"
                ),
            ));
        }
    }
    if let Some(i) = xyz.iter().position(|c| !c.is_finite()) {
        let (a, b) = spans[i];
        return Err((a, b, "vertex coordinate is not a finite number".to_string()));
    }
    Ok(())
}

/// Checks one `v`, `v/vt`, `v//vn` or `v/vt/vn` word of a face. Relative (negative) indices
/// count back from the elements defined so far; positive ones must exist by the end of the
/// file, so the largest is kept for that check.
fn face_vertex(s: &mut Scan, at: usize, word: &str, line_no: u64) -> Result<(), LineProblem> {
    let whole = (at, at + word.len());
    // In place, not collected: this runs on every corner of every face.
    let mut parts = [""; 3];
    let mut count = 0;
    for part in word.split('/') {
        if count == parts.len() {
            return Err((
                whole.0,
                whole.1,
                format!("expected a face vertex v, v/vt, v//vn or v/vt/vn, found '{word}'"),
            ));
        }
        parts[count] = part;
        count += 1;
    }
    let parts = &parts[..count];
    let mut offset = at;
    for (kind, part) in parts.iter().enumerate() {
        let span = (offset, offset + part.len());
        offset += part.len() + 1;
        if part.is_empty() {
            if kind == 0 {
                return Err((
                    whole.0,
                    whole.1,
                    format!("face vertex '{word}' gives no vertex index"),
                ));
            }
            continue;
        }
        let index: i64 = part.parse().map_err(|_| {
            (
                span.0,
                span.1,
                format!(
                    "expected a {} index (a whole number), found '{part}'",
                    KINDS[kind]
                ),
            )
        })?;
        let defined = s.counts[kind];
        if index == 0 {
            return Err((
                span.0,
                span.1,
                format!("{} index 0: OBJ indices count from 1", KINDS[kind]),
            ));
        }
        if index < 0 {
            if defined == 0 && kind != 0 && s.early[kind].is_none() {
                s.early[kind] = Some(Farthest {
                    index: index.unsigned_abs(),
                    line: line_no,
                    start: span.0,
                    end: span.1,
                });
            }
            if index.unsigned_abs() > defined && (kind == 0 || defined > 0) {
                return Err((
                    span.0,
                    span.1,
                    format!(
                        "relative {} index {index} reaches before the first one ({defined} defined so far)",
                        KINDS[kind]
                    ),
                ));
            }
        } else if index as u64 > s.farthest[kind].index {
            s.farthest[kind] = Farthest {
                index: index as u64,
                line: line_no,
                start: span.0,
                end: span.1,
            };
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scan_str(text: &str) -> Result<Scan, Problem> {
        scan(text.as_bytes())
    }

    fn problem(text: &str) -> (u64, usize, String) {
        let p = scan_str(text).unwrap_err();
        (p.line, p.start, p.message)
    }

    #[test]
    fn counts_triangles_after_fan_triangulation() {
        let s =
            scan_str("v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\nf 1 2 3\nl 1 2\n").unwrap();
        assert_eq!(s.counts, [4, 0, 0]);
        assert_eq!(s.triangles, 3);
    }

    #[test]
    fn relative_and_slashed_indices_are_accepted() {
        let s = scan_str("v 0 0 0\nv 1 0 0\nv 1 1 0\nvn 0 0 1\nf -3//1 -2//1 -1//-1\n").unwrap();
        assert_eq!(s.triangles, 1);
    }

    /// Found by the fuzz harness: a relative normal index before any normal, in a file that
    /// defines one later, made `tobj` overflow (a panic where overflow is checked).
    #[test]
    fn a_relative_index_before_the_first_of_its_kind_is_refused_if_one_comes_later() {
        let early = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -3//-1 -2//-1 -1//-1\n";
        assert!(
            scan_str(early).is_ok(),
            "no normal at all: the index is ignored"
        );
        let problem = scan_str(&format!("{early}vn 0 0 1\n")).unwrap_err();
        assert_eq!((problem.line, problem.start, problem.end), (4, 6, 8));
        assert_eq!(
            problem.message,
            "relative normal index -1 reaches before the first one (0 defined so far)"
        );
    }

    #[test]
    fn problems_point_at_the_culprit() {
        let (line, start, msg) = problem("v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 4\n");
        assert_eq!((line, start), (4, 6), "{msg}");
        assert!(msg.contains("vertex 4 but the file defines 3"), "{msg}");
        let (line, start, msg) = problem("v 0 0 0\nv 1 nan 0\n");
        assert_eq!((line, start), (2, 4));
        assert!(msg.contains("not a finite number"));
        let (line, start, msg) = problem("v 0 0 0\nv 1 0x 0\n");
        assert_eq!((line, start), (2, 4));
        assert!(msg.contains("found '0x'"), "{msg}");
        let (line, start, msg) = problem("v 0 0\n");
        assert_eq!((line, start), (1, 5));
        assert!(msg.contains("end of line"), "{msg}");
        let (line, start, msg) = problem("v 0 0 0\nf 1 0 1\n");
        assert_eq!((line, start), (2, 4));
        assert!(msg.contains("count from 1"));
        let (line, start, _) = problem("v 0 0 0\nf 1 -2 1\n");
        assert_eq!((line, start), (2, 4));
        let (line, start, msg) = problem("v 0 0 0\nf 1/2/3/4 1 1\n");
        assert_eq!((line, start), (2, 2));
        assert!(msg.contains("v/vt/vn"));
        let (line, start, _) = problem("v 0 0 0 1 1\n");
        assert_eq!((line, start), (1, 8));
        let (line, _, msg) = problem("v 0 0 0 0\n");
        assert_eq!(line, 1);
        assert!(msg.contains("weight"));
        let (line, start, _) = problem("usemtl\n");
        assert_eq!((line, start), (1, 6));
    }

    #[test]
    fn every_index_names_what_the_file_defines() {
        // No `vt` or `vn` lines at all: a face naming one is an error, at the farthest.
        let (line, start, msg) = problem("v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1/7 2/7 3/9\n");
        assert_eq!((line, start), (4, 12), "{msg}");
        assert!(
            msg.contains("texture coordinate 9 but the file defines 0"),
            "{msg}"
        );
        let (line, _, msg) = problem("v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1//1 2//1 3//1\n");
        assert_eq!(line, 4);
        assert!(msg.contains("normal 1 but the file defines 0"), "{msg}");
        // Some normals defined: an index past them is an error.
        let (line, start, msg) = problem("v 0 0 0\nv 1 0 0\nv 1 1 0\nvn 0 0 1\nf 1//1 2//2 3//1\n");
        assert_eq!((line, start), (5, 10));
        assert!(msg.contains("normal 2"), "{msg}");
    }

    /// Whatever its line endings and a leading byte order mark, a file reads as an editor
    /// shows it, whatever the reader's buffer size.
    #[test]
    fn line_endings_and_byte_order_marks_read_as_an_editor_shows_them() {
        let normal = |text: &str, capacity: usize| {
            let mut out = String::new();
            let mut lines = ObjLines::new(BufReader::with_capacity(capacity, text.as_bytes()));
            lines.read_to_string(&mut out).unwrap();
            out
        };
        let text = "\u{feff}v 0 0 0\rv 1 0 0\r\nv 0 1 0\n\rl 1 2 3\r  f 1 2 3";
        for capacity in [1, 2, 3, 5, 64] {
            assert_eq!(
                normal(text, capacity),
                "v 0 0 0\nv 1 0 0\nv 0 1 0\n\n#  1 2 3\n  f 1 2 3\n".replace("#  1", "# 1"),
                "buffer of {capacity}"
            );
        }
        let dir = tempfile::tempdir().unwrap();
        let old_mac = dir.path().join("mac.obj");
        std::fs::write(&old_mac, "\u{feff}v 0 0 0\rv 1 0 0\rv 0 1 0\rf 1 2 3\r").unwrap();
        assert_eq!(load(&old_mac, u64::MAX).unwrap().triangle_count(), 1);
        std::fs::write(&old_mac, "v 0 0 0\rv 1 0 0\rf 1 2 3\r").unwrap();
        let d = load(&old_mac, u64::MAX).unwrap_err();
        let loc = d.loc.clone().unwrap();
        assert_eq!((loc.line, loc.col), (3, 7), "{d:?}");
    }

    /// What cannot be a mesh is refused before it costs memory or time: a pipe (opening it
    /// would wait for a writer), a file over the input limit, a line without end, NUL bytes.
    #[test]
    fn pipes_huge_files_endless_lines_and_nul_bytes_are_refused_early() {
        let dir = tempfile::tempdir().unwrap();
        let pipe = dir.path().join("pipe.obj");
        let made = std::process::Command::new("mkfifo")
            .arg(&pipe)
            .status()
            .unwrap();
        assert!(made.success());
        let d = load(&pipe, u64::MAX).unwrap_err();
        assert!(d.message.contains("not a regular file"), "{d:?}");
        let sparse = dir.path().join("sparse.obj");
        std::fs::File::create(&sparse)
            .unwrap()
            .set_len(3 << 20)
            .unwrap();
        let d = load(&sparse, 1 << 20).unwrap_err();
        assert!(
            d.message.contains("too large to read: 3145728 bytes"),
            "{d:?}"
        );
        let d = load(&sparse, u64::MAX).unwrap_err();
        assert!(d.message.contains("NUL"), "{d:?}");
        let endless = dir.path().join("endless.obj");
        let line = "v 0 0 0\n".to_string() + &"1".repeat(MAX_OBJ_LINE_BYTES + 1);
        std::fs::write(&endless, line).unwrap();
        let d = load(&endless, u64::MAX).unwrap_err();
        assert!(d.message.contains("longer than"), "{d:?}");
        assert_eq!(d.loc.map(|l| l.line), Some(2));
    }

    /// A polyline (`l`) draws nothing, however many points it has: a file with a face and
    /// polylines holds the face alone, and a file of polylines holds no triangles.
    #[test]
    fn polylines_draw_nothing() {
        let dir = tempfile::tempdir().unwrap();
        let points = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n";
        let with_face = dir.path().join("face.obj");
        std::fs::write(
            &with_face,
            format!("{points}l 2 3 4\nf 1 2 3\n  l 1 2 3 4\nl 1 2\n"),
        )
        .unwrap();
        let mesh = load(&with_face, u64::MAX).unwrap();
        assert_eq!(mesh.triangle_count(), 1);
        let lines_only = dir.path().join("lines.obj");
        std::fs::write(&lines_only, format!("{points}l 1 2 3\n")).unwrap();
        let d = load(&lines_only, u64::MAX).unwrap_err();
        assert!(d.message.contains("no triangles"), "{d:?}");
    }

    #[test]
    fn folders_and_devices_are_refused_before_reading() {
        let dir = std::env::temp_dir();
        let mut paths = vec![dir.as_path()];
        // A device never ends its first line: it must not be read at all.
        if Path::new("/dev/zero").exists() {
            paths.push(Path::new("/dev/zero"));
        }
        for p in paths {
            let d = load(p, u64::MAX).unwrap_err();
            assert!(
                d.loc.is_none() && d.message.contains("cannot be read"),
                "{d:?}"
            );
        }
    }

    /// A mesh is refused after the pass that counts it when the budget cannot hold what
    /// `limits::mesh_memory` says it needs, and read when it can.
    #[test]
    fn a_mesh_beyond_the_memory_budget_is_refused_before_it_is_read() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("quad.obj");
        std::fs::write(&path, "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n").unwrap();
        let needed = crate::limits::mesh_memory(4, 2);
        let file = File::open(&path).unwrap();
        let mesh = load_open(&file, &path, u64::MAX, needed).unwrap();
        assert_eq!(mesh.triangle_count(), 2);
        let d = load_open(&file, &path, u64::MAX, needed - 1).unwrap_err();
        let expected = format!(
            "needs about {} of memory to read and build its 2 triangles, more than the {} allowed",
            human_bytes(needed),
            human_bytes(needed - 1)
        );
        assert_eq!((d.loc, d.message), (None, expected));
        assert_eq!(d.help.as_deref(), Some(crate::limits::RAISE_MEMORY));
    }

    #[test]
    fn not_utf8_is_located() {
        let p = scan(&b"v 0 0 0\nv \xff 0 0\n"[..]).unwrap_err();
        assert_eq!((p.line, p.start), (2, 2));
    }
}
