//! The preview's web server: a fixed set of routes over what is in memory (the page, the
//! state, the frames) and the one export file in the preview's temporary folder. Nothing a URL
//! says is ever taken as a path: a request is refused unless its path is one of the routes,
//! and unless its `Host` header names the address the server bound (DNS rebinding).

use super::export::{self, Export};
use super::http::{self, Answer, Connection, Method, ReadError, Request};
use super::state::Shared;
use std::collections::VecDeque;
use std::io::Read as _;
use std::net::{Shutdown, SocketAddr, TcpListener, TcpStream};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

const INDEX: &str = include_str!("page/index.html");
const SCRIPT: &str = include_str!("page/app.js");
const STYLE: &str = include_str!("page/style.css");

/// Event streams open at once: a newer one closes the oldest, so pages left open in many tabs
/// (or a client holding streams) can neither hold every connection nor lock out a new page.
const MAX_STREAMS: usize = 32;

/// What a request asks for, once its path has been checked.
#[derive(Debug, PartialEq, Eq)]
pub enum Route {
    Page,
    Script,
    Style,
    State,
    Events,
    Frame(usize),
    Focus(usize),
    Export,
    Download,
}

/// The route of `url` for `method`, or the status that refuses it. Only the exact paths of
/// the routes are served: anything with `..`, a backslash, a percent escape (which could hide
/// either), an empty segment or a scheme is refused before it is looked at further.
pub fn route(method: &Method, url: &str) -> Result<Route, u16> {
    let (path, query) = url.split_once('?').unwrap_or((url, ""));
    let suspicious = !path.starts_with('/')
        || path.contains("..")
        || path.contains('\\')
        || path.contains('%')
        || path.contains("//")
        || path.bytes().any(|b| b.is_ascii_control());
    if suspicious {
        return Err(400);
    }
    let get = matches!(method, Method::Get | Method::Head);
    let post = *method == Method::Post;
    let route = match path {
        "/" | "/index.html" if get => Route::Page,
        "/app.js" if get => Route::Script,
        "/style.css" if get => Route::Style,
        "/api/state" if get => Route::State,
        "/events" if get => Route::Events,
        "/api/focus" if post => Route::Focus(query_number(query, "frame").ok_or(400u16)?),
        "/api/export" if post => Route::Export,
        "/export/preview.mp4" if get => Route::Download,
        _ => {
            let index = path
                .strip_prefix("/frame/")
                .and_then(|p| p.strip_suffix(".png"))
                .filter(|n| !n.is_empty() && n.bytes().all(|b| b.is_ascii_digit()))
                .and_then(|n| n.parse().ok());
            match index {
                Some(i) if get => Route::Frame(i),
                Some(_) => return Err(405),
                None => return Err(404),
            }
        }
    };
    Ok(route)
}

fn query_number(query: &str, name: &str) -> Option<usize> {
    query
        .split('&')
        .find_map(|kv| kv.strip_prefix(name)?.strip_prefix('='))
        .and_then(|v| v.parse().ok())
}

/// Whether `host` (the `Host` header) names the address the server bound. A page of another
/// site that reaches this port through a name it controls (DNS rebinding) sends that name, so
/// only IP literals are taken (any of the machine's, when bound to all of them), and
/// `localhost`, which no other site can make resolve here.
pub fn host_ok(host: Option<&str>, bound: SocketAddr) -> bool {
    let Some(host) = host.map(str::trim) else {
        return false;
    };
    let with_port = if host.ends_with(']') || !host.contains(':') {
        format!("{host}:80")
    } else {
        host.to_string()
    };
    let any = bound.ip().is_unspecified();
    if let Some(name) = with_port.strip_suffix(&format!(":{}", bound.port())) {
        if name.eq_ignore_ascii_case("localhost") {
            return bound.ip().is_loopback() || any;
        }
    }
    match with_port.parse::<SocketAddr>() {
        Ok(addr) => addr.port() == bound.port() && (addr.ip() == bound.ip() || any),
        Err(_) => false,
    }
}

/// What every request handler needs.
pub struct Context {
    pub shared: Arc<Shared>,
    pub bound: SocketAddr,
    pub export: Arc<Export>,
    /// The open event streams, oldest first: each with what closes it.
    streams: Mutex<VecDeque<Stream>>,
    next_stream: AtomicU64,
}

/// An open event stream, as the others see it.
struct Stream {
    id: u64,
    /// Set when a newer page took its place; its thread then ends.
    ended: Arc<AtomicBool>,
    closer: Option<TcpStream>,
}

impl Context {
    pub fn new(shared: Arc<Shared>, bound: SocketAddr, export: Export) -> Self {
        Context {
            shared,
            bound,
            export: Arc::new(export),
            streams: Mutex::default(),
            next_stream: AtomicU64::new(0),
        }
    }

    fn streams(&self) -> std::sync::MutexGuard<'_, VecDeque<Stream>> {
        self.streams.lock().unwrap_or_else(|e| e.into_inner())
    }
}

/// Answers requests on `listener` until the preview stops.
pub fn serve(listener: &TcpListener, ctx: Context) {
    let ctx = Arc::new(ctx);
    let pool = Arc::new(http::Pool::default());
    let shared = ctx.shared.clone();
    http::accept_loop(
        listener,
        &pool,
        || shared.lock().stop,
        move |connection| converse(connection, &ctx),
    );
}

/// What a request gets: an answer, the export file, or an event stream.
enum Reply {
    Answer(Answer),
    File(std::fs::File),
    Events,
}

/// Answers one client's requests, in order, until it goes away or an answer ends it.
fn converse(mut connection: Connection, ctx: &Context) {
    loop {
        let request = match connection.next_request() {
            Ok(request) => request,
            Err(ReadError::Gone) => return,
            Err(ReadError::Bad(status)) => {
                connection.respond(None, &plain(status, "bad request"));
                return;
            }
        };
        let go_on = match handle(&request, ctx) {
            Reply::Answer(answer) => connection.respond(Some(&request), &answer),
            Reply::File(file) => send_file(&mut connection, &request, file),
            Reply::Events => return stream(connection, ctx),
        };
        if !go_on {
            return;
        }
    }
}

/// The headers every answer of this server carries, with `kind` as its type.
fn answer(status: u16, kind: &str, body: Vec<u8>) -> Answer {
    let headers = [
        ("Content-Type", kind),
        ("Cache-Control", "no-store"),
        ("X-Content-Type-Options", "nosniff"),
        (
            "Content-Security-Policy",
            "default-src 'self'; img-src 'self' blob:; media-src 'self'",
        ),
    ];
    Answer {
        status,
        headers: headers.iter().map(|(n, v)| (*n, v.to_string())).collect(),
        body,
    }
}

fn plain(status: u16, why: &str) -> Answer {
    answer(status, "text/plain; charset=utf-8", why.as_bytes().to_vec())
}

fn handle(request: &Request, ctx: &Context) -> Reply {
    let host = request.header("Host");
    if !host_ok(host, ctx.bound) {
        return Reply::Answer(plain(421, "unknown host"));
    }
    let route = match route(&request.method, &request.url) {
        Ok(route) => route,
        Err(status) => return Reply::Answer(plain(status, "not served")),
    };
    // Another site's page may post to this address directly (its Host is then right): a
    // browser names that page's origin, which must be this one.
    let foreign = request.header("Origin").is_some_and(|origin| {
        host.is_none_or(|h| !origin.eq_ignore_ascii_case(&format!("http://{}", h.trim())))
    });
    if request.method == Method::Post && foreign {
        return Reply::Answer(plain(403, "posted from another site"));
    }
    let text = |kind: &str, body: &str| Reply::Answer(answer(200, kind, body.into()));
    match route {
        Route::Page => text("text/html; charset=utf-8", INDEX),
        Route::Script => text("text/javascript; charset=utf-8", SCRIPT),
        Route::Style => text("text/css; charset=utf-8", STYLE),
        Route::State => {
            let json = ctx.shared.lock().to_json();
            text("application/json", &json)
        }
        Route::Frame(i) => {
            let png = ctx
                .shared
                .lock()
                .frames
                .get(i)
                .and_then(|f| f.best().map(|(img, _)| img.png.clone()));
            match png {
                Some(png) => Reply::Answer(answer(200, "image/png", png.to_vec())),
                None => Reply::Answer(plain(404, "no image yet")),
            }
        }
        Route::Focus(i) => {
            let mut state = ctx.shared.lock();
            state.playhead = i.min(state.frames.len().saturating_sub(1));
            ctx.shared.work.notify_all();
            drop(state);
            text("application/json", "{}")
        }
        Route::Events => Reply::Events,
        // Encoding takes seconds: this connection waits, the others are answered meanwhile.
        Route::Export => text("application/json", &export::run(&ctx.shared, &ctx.export)),
        Route::Download => match std::fs::File::open(ctx.export.video()) {
            Ok(file) => Reply::File(file),
            Err(_) => Reply::Answer(plain(404, "nothing exported yet")),
        },
    }
}

/// Sends the exported video, read as it is sent.
fn send_file(connection: &mut Connection, request: &Request, mut file: std::fs::File) -> bool {
    let len = file.metadata().map_or(0, |m| m.len());
    let mut head = answer(200, "video/mp4", Vec::new());
    head.headers.push((
        "Content-Disposition",
        "attachment; filename=\"preview.mp4\"".to_string(),
    ));
    if !connection.respond_head(Some(request), &head, len) {
        return false;
    }
    let go_on = !request.close();
    if request.method == Method::Head {
        return go_on;
    }
    let mut chunk = vec![0u8; 64 << 10];
    let mut left = len;
    while left > 0 {
        let n = match file.read(&mut chunk) {
            Ok(0) | Err(_) => return false,
            Ok(n) => n.min(usize::try_from(left).unwrap_or(usize::MAX)),
        };
        if !connection.write(&chunk[..n]) {
            return false;
        }
        left -= n as u64;
    }
    go_on
}

/// How often an idle event stream says it is still there.
const STILL_HERE: Duration = Duration::from_secs(15);
/// The shortest time between two events of a stream.
const EVENT_GAP: Duration = Duration::from_millis(100);

/// Server-Sent Events until the page goes away, a newer page takes its place or the preview
/// stops: the whole state first, then, at most ten times a second, what changed (`event:
/// delta`: the frames whose marks changed, the notes only when they did).
fn stream(mut connection: Connection, ctx: &Context) {
    let id = ctx.next_stream.fetch_add(1, Ordering::Relaxed);
    let ended = Arc::new(AtomicBool::new(false));
    {
        let mut streams = ctx.streams();
        // The newest page wins: pages left open, or a client holding streams, give way.
        while streams.len() >= MAX_STREAMS {
            let Some(oldest) = streams.pop_front() else {
                break;
            };
            oldest.ended.store(true, Ordering::SeqCst);
            if let Some(closer) = oldest.closer {
                let _ = closer.shutdown(Shutdown::Both);
            }
        }
        streams.push_back(Stream {
            id,
            ended: ended.clone(),
            closer: connection.closer(),
        });
    }
    let head = "HTTP/1.1 200 OK\r\nContent-Type: text/event-stream\r\nCache-Control: no-store\r\nConnection: close\r\n\r\n";
    if connection.write(head.as_bytes()) {
        events(&mut connection, &ctx.shared, &ended);
    }
    ctx.streams().retain(|s| s.id != id);
}

fn events(connection: &mut Connection, shared: &Shared, ended: &AtomicBool) {
    let mut seen = u64::MAX;
    let mut marks: Vec<u64> = Vec::new();
    let mut notes = 0;
    let mut quiet = Instant::now();
    while !ended.load(Ordering::SeqCst) {
        let mut state = shared.lock();
        if state.version == seen && !state.stop {
            // Waits a little at a time, so that a stream another page replaced ends soon.
            state = shared.wait(&shared.changed, state, Duration::from_secs(1));
        }
        if state.stop {
            return;
        }
        let message = if state.version != seen {
            let first = seen == u64::MAX;
            seen = state.version;
            let now = state.frame_marks();
            let now_notes = state.notes_mark();
            let delta = state
                .delta_json(&marks, &now, now_notes != notes)
                .filter(|_| !first);
            marks = now;
            notes = now_notes;
            match delta {
                Some(delta) => format!("event: delta\ndata: {delta}\n\n"),
                None => format!("data: {}\n\n", state.to_json()),
            }
        } else if quiet.elapsed() >= STILL_HERE {
            ": still here\n\n".to_string()
        } else {
            continue;
        };
        drop(state);
        if !connection.write(message.as_bytes()) {
            return;
        }
        quiet = Instant::now();
        std::thread::sleep(EVENT_GAP);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_the_routes_are_served() {
        let get = Method::Get;
        assert_eq!(route(&get, "/"), Ok(Route::Page));
        assert_eq!(route(&get, "/frame/12.png?v=3"), Ok(Route::Frame(12)));
        for bad in [
            "/../etc/passwd",
            "/frame/../../x",
            "/%2e%2e/etc/passwd",
            "/%2E%2E%2Fetc",
            "//etc/passwd",
            "\\..\\x",
            "http://evil/",
        ] {
            assert_eq!(route(&get, bad), Err(400), "{bad}");
        }
        assert_eq!(route(&get, "/etc/passwd"), Err(404));
        assert_eq!(route(&get, "/frame/-1.png"), Err(404));
        assert_eq!(route(&Method::Post, "/frame/1.png"), Err(405));
        assert_eq!(
            route(&Method::Post, "/api/focus?frame=4"),
            Ok(Route::Focus(4))
        );
    }

    #[test]
    fn only_the_bound_host_is_answered() {
        let local: SocketAddr = "127.0.0.1:8000".parse().unwrap();
        assert!(host_ok(Some("127.0.0.1:8000"), local));
        assert!(host_ok(Some("localhost:8000"), local));
        assert!(host_ok(Some("LOCALHOST:8000"), local));
        assert!(!host_ok(Some("evil.example:8000"), local));
        assert!(!host_ok(Some("evil.example"), local));
        assert!(!host_ok(Some("127.0.0.1:8001"), local));
        assert!(!host_ok(Some("127.0.0.2:8000"), local));
        assert!(!host_ok(None, local));
        let lan: SocketAddr = "10.0.0.2:8000".parse().unwrap();
        assert!(!host_ok(Some("localhost:8000"), lan));
        assert!(host_ok(Some("10.0.0.2:8000"), lan));
        let all: SocketAddr = "0.0.0.0:80".parse().unwrap();
        assert!(host_ok(Some("192.168.1.5"), all));
        assert!(host_ok(Some("[::1]:80"), "[::]:80".parse().unwrap()));
        assert!(!host_ok(Some("rebind.example"), all));
    }
}
