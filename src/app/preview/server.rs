//! The preview's web server: a fixed set of routes over what is in memory (the page, the
//! state, the frames) and the one export file in the preview's temporary folder. Nothing a URL
//! says is ever taken as a path: a request is refused unless its path is one of the routes,
//! and unless its `Host` header names the address the server bound (DNS rebinding).

use super::export::{self, Export};
use super::state::Shared;
use std::io::Write as _;
use std::net::SocketAddr;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Arc;
use std::time::Duration;
use tiny_http::{Header, Method, Request, Response, Server};

const INDEX: &str = include_str!("page/index.html");
const SCRIPT: &str = include_str!("page/app.js");
const STYLE: &str = include_str!("page/style.css");

/// Event streams open at once; more are refused, so a page left open in many tabs cannot
/// hold every thread.
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
    streams: Arc<AtomicUsize>,
}

impl Context {
    pub fn new(shared: Arc<Shared>, bound: SocketAddr, export: Export) -> Self {
        Context {
            shared,
            bound,
            export: Arc::new(export),
            streams: Arc::default(),
        }
    }
}

/// Answers requests until the preview stops.
pub fn serve(server: &Server, ctx: &Context) -> std::io::Result<()> {
    while !ctx.shared.lock().stop {
        if let Some(request) = server.recv_timeout(Duration::from_millis(100))? {
            handle(request, ctx);
        }
    }
    Ok(())
}

/// `response` with `headers` (fixed ASCII strings of this file, which always make headers).
fn with_headers<R: std::io::Read>(
    mut response: Response<R>,
    headers: &[(&str, &str)],
) -> Response<R> {
    for (name, value) in headers {
        if let Ok(h) = Header::from_bytes(name.as_bytes(), value.as_bytes()) {
            response.add_header(h);
        }
    }
    response
}

fn respond(request: Request, status: u16, kind: &str, body: Vec<u8>) {
    let response = with_headers(
        Response::from_data(body).with_status_code(status),
        &[
            ("Content-Type", kind),
            ("Cache-Control", "no-store"),
            ("X-Content-Type-Options", "nosniff"),
            (
                "Content-Security-Policy",
                "default-src 'self'; img-src 'self' blob:; media-src 'self'",
            ),
        ],
    );
    // The browser may have gone away; there is no one to tell.
    let _ = request.respond(response);
}

fn refuse(request: Request, status: u16, why: &str) {
    respond(
        request,
        status,
        "text/plain; charset=utf-8",
        why.as_bytes().to_vec(),
    );
}

/// The value of header `name`, if the request has it.
fn header_value(request: &Request, name: &'static str) -> Option<String> {
    request
        .headers()
        .iter()
        .find(|h| h.field.equiv(name))
        .map(|h| h.value.as_str().to_string())
}

fn handle(request: Request, ctx: &Context) {
    let host = header_value(&request, "Host");
    if !host_ok(host.as_deref(), ctx.bound) {
        return refuse(request, 421, "unknown host");
    }
    let route = match route(request.method(), request.url()) {
        Ok(route) => route,
        Err(status) => return refuse(request, status, "not served"),
    };
    // Another site's page may post to this address directly (its Host is then right): a
    // browser names that page's origin, which must be this one.
    let foreign = header_value(&request, "Origin").is_some_and(|origin| {
        host.as_deref()
            .is_none_or(|h| !origin.eq_ignore_ascii_case(&format!("http://{}", h.trim())))
    });
    if *request.method() == Method::Post && foreign {
        return refuse(request, 403, "posted from another site");
    }
    let text = |request, kind: &str, body: &str| respond(request, 200, kind, body.into());
    match route {
        Route::Page => text(request, "text/html; charset=utf-8", INDEX),
        Route::Script => text(request, "text/javascript; charset=utf-8", SCRIPT),
        Route::Style => text(request, "text/css; charset=utf-8", STYLE),
        Route::State => {
            let json = ctx.shared.lock().to_json();
            text(request, "application/json", &json)
        }
        Route::Frame(i) => {
            let png = ctx
                .shared
                .lock()
                .frames
                .get(i)
                .and_then(|f| f.best().map(|(img, _)| img.png.clone()));
            match png {
                Some(png) => respond(request, 200, "image/png", png.to_vec()),
                None => refuse(request, 404, "no image yet"),
            }
        }
        Route::Focus(i) => {
            let mut state = ctx.shared.lock();
            state.playhead = i.min(state.frames.len().saturating_sub(1));
            ctx.shared.work.notify_all();
            drop(state);
            text(request, "application/json", "{}")
        }
        Route::Events => stream(request, ctx),
        Route::Export => {
            let (shared, export) = (ctx.shared.clone(), ctx.export.clone());
            // Encoding takes seconds; the server goes on answering meanwhile.
            std::thread::spawn(move || {
                let json = export::run(&shared, &export);
                respond(request, 200, "application/json", json.into_bytes());
            });
        }
        Route::Download => match std::fs::File::open(ctx.export.video()) {
            Ok(file) => {
                let response = with_headers(
                    Response::from_file(file),
                    &[
                        ("Content-Type", "video/mp4"),
                        (
                            "Content-Disposition",
                            "attachment; filename=\"preview.mp4\"",
                        ),
                    ],
                );
                let _ = request.respond(response);
            }
            Err(_) => refuse(request, 404, "nothing exported yet"),
        },
    }
}

/// Server-Sent Events: the whole state each time it changes, at most ten times a second,
/// on a thread of its own until the page goes away or the preview stops.
fn stream(request: Request, ctx: &Context) {
    if ctx.streams.fetch_add(1, Ordering::SeqCst) >= MAX_STREAMS {
        ctx.streams.fetch_sub(1, Ordering::SeqCst);
        return refuse(request, 503, "too many open pages");
    }
    let shared = ctx.shared.clone();
    let streams = ctx.streams.clone();
    std::thread::spawn(move || {
        let mut out = request.into_writer();
        let head = "HTTP/1.1 200 OK\r\nContent-Type: text/event-stream\r\nCache-Control: no-store\r\nConnection: close\r\n\r\n";
        let mut seen = u64::MAX;
        let mut ok = out.write_all(head.as_bytes()).is_ok();
        while ok {
            let mut state = shared.lock();
            if state.version == seen && !state.stop {
                state = shared.wait(&shared.changed, state, Duration::from_secs(15));
            }
            if state.stop {
                break;
            }
            let message = if state.version == seen {
                ": still here\n\n".to_string()
            } else {
                seen = state.version;
                format!("data: {}\n\n", state.to_json())
            };
            drop(state);
            ok = out.write_all(message.as_bytes()).is_ok() && out.flush().is_ok();
            std::thread::sleep(Duration::from_millis(100));
        }
        streams.fetch_sub(1, Ordering::SeqCst);
    });
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
