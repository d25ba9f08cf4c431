//! The preview's HTTP/1.1 connections, bounded so that no client can take the server from
//! another: one accept loop that never gives up (a full file table or a failed thread only
//! drops that connection), a cap on the connections open at once (at the cap, the one that
//! has waited longest for its request head is closed to make room), a deadline for a whole
//! request head and body (a client that sends a byte a second cannot hold a connection), caps
//! on their sizes, and a write timeout on every answer (a client that never reads holds only
//! its own connection, never a lock, until it is closed).

use std::collections::VecDeque;
use std::io::{ErrorKind, Read, Write};
use std::net::{Shutdown, TcpListener, TcpStream};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex, MutexGuard};
use std::time::{Duration, Instant};

/// Connections open at once, event streams included.
pub const MAX_CONNECTIONS: usize = 128;
/// Time a client has from its connection (or its previous answer) to the end of its request.
pub const REQUEST_DEADLINE: Duration = Duration::from_secs(5);
/// Time an answer may wait for the client to take its bytes.
pub const WRITE_TIMEOUT: Duration = Duration::from_secs(5);
/// Largest request head (request line and headers).
const MAX_HEAD: usize = 16 << 10;
/// Largest request body (the routes take none; a browser's POST may carry a small one).
const MAX_BODY: usize = 64 << 10;
/// How often the accept loop looks whether the preview stopped.
const POLL: Duration = Duration::from_millis(20);
/// Each connection's thread: answers are built on the heap, so a small stack will do.
const STACK: usize = 256 << 10;

/// A request's method.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Method {
    Get,
    Head,
    Post,
    Other,
}

/// A request as read from the socket: its method, target and headers (the body is read and
/// dropped: no route takes one).
#[derive(Debug)]
pub struct Request {
    pub method: Method,
    pub url: String,
    headers: Vec<(String, String)>,
    /// Whether the client asked to close the connection after this answer.
    close: bool,
}

impl Request {
    /// Whether the connection closes after the answer to this request.
    pub fn close(&self) -> bool {
        self.close
    }

    /// The value of header `name` (ASCII case ignored), if the request has it.
    pub fn header(&self, name: &str) -> Option<&str> {
        self.headers
            .iter()
            .find(|(n, _)| n.eq_ignore_ascii_case(name))
            .map(|(_, v)| v.as_str())
    }
}

/// Why reading a request ended without one.
#[derive(Debug, PartialEq, Eq)]
pub enum ReadError {
    /// The client closed, went quiet past the deadline, or the server closed the connection.
    Gone,
    /// A request that is not HTTP/1.x as the server reads it: answer with this status, close.
    Bad(u16),
}

/// The connections that are open: how many, and those waiting for a request, oldest first,
/// each with a handle that can close it.
#[derive(Default)]
struct Open {
    count: usize,
    waiting: VecDeque<(u64, TcpStream)>,
}

/// Everything the accept loop shares with the connections' threads.
#[derive(Default)]
pub struct Pool {
    open: Mutex<Open>,
    next_id: AtomicU64,
}

impl Pool {
    fn lock(&self) -> MutexGuard<'_, Open> {
        self.open.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// Takes a place for a new connection: when every place is taken, the connection that has
    /// waited longest for its request is closed to make room; `false` if none is waiting.
    fn admit(&self) -> bool {
        let mut open = self.lock();
        if open.count >= MAX_CONNECTIONS {
            match open.waiting.pop_front() {
                // Its thread sees the end of its stream and gives its place back.
                Some((_, idle)) => drop(idle.shutdown(Shutdown::Both)),
                None => return false,
            }
        }
        open.count += 1;
        true
    }

    fn leave(&self, id: u64) {
        let mut open = self.lock();
        open.count = open.count.saturating_sub(1);
        open.waiting.retain(|(i, _)| *i != id);
    }

    fn set_waiting(&self, id: u64, stream: &TcpStream, waiting: bool) {
        let mut open = self.lock();
        open.waiting.retain(|(i, _)| *i != id);
        if waiting {
            // Without a second handle the connection cannot be closed from here: it then
            // waits out its deadline like any other.
            if let Ok(handle) = stream.try_clone() {
                open.waiting.push_back((id, handle));
            }
        }
    }
}

/// One client's connection, on a thread of its own.
pub struct Connection {
    stream: TcpStream,
    id: u64,
    pool: Arc<Pool>,
    /// Bytes read past the end of the last request (a pipelining client's next requests).
    buffered: Vec<u8>,
}

impl Drop for Connection {
    fn drop(&mut self) {
        self.pool.leave(self.id);
    }
}

impl Connection {
    /// Reads the next request, within [`REQUEST_DEADLINE`] from now.
    pub fn next_request(&mut self) -> Result<Request, ReadError> {
        self.pool.set_waiting(self.id, &self.stream, true);
        let deadline = Instant::now() + REQUEST_DEADLINE;
        let read = self.read_request(deadline);
        self.pool.set_waiting(self.id, &self.stream, false);
        read
    }

    fn read_request(&mut self, deadline: Instant) -> Result<Request, ReadError> {
        let head_end = loop {
            if let Some(end) = head_end(&self.buffered) {
                break end;
            }
            if self.buffered.len() > MAX_HEAD {
                return Err(ReadError::Bad(431));
            }
            self.fill(deadline)?;
        };
        let head: Vec<u8> = self.buffered.drain(..head_end).collect();
        let request = parse_head(&head)?;
        let length = match request.header("Content-Length") {
            None => 0,
            Some(v) => v.trim().parse::<usize>().map_err(|_| ReadError::Bad(400))?,
        };
        if request.header("Transfer-Encoding").is_some() {
            return Err(ReadError::Bad(501));
        }
        if length > MAX_BODY {
            return Err(ReadError::Bad(413));
        }
        while self.buffered.len() < length {
            self.fill(deadline)?;
        }
        self.buffered.drain(..length);
        Ok(request)
    }

    /// Reads what the client sent next, waiting no later than `deadline`.
    fn fill(&mut self, deadline: Instant) -> Result<(), ReadError> {
        let left = deadline.saturating_duration_since(Instant::now());
        if left.is_zero() || self.stream.set_read_timeout(Some(left)).is_err() {
            return Err(ReadError::Gone);
        }
        let mut chunk = [0u8; 4096];
        match self.stream.read(&mut chunk) {
            Ok(0) | Err(_) => Err(ReadError::Gone),
            Ok(n) => {
                self.buffered.extend_from_slice(&chunk[..n]);
                Ok(())
            }
        }
    }

    /// Writes a whole answer (its head alone for `HEAD`); whether the connection goes on
    /// (`false` when the client is gone, does not read, or the connection closes after it).
    /// `request` is `None` for a request that could not be read.
    pub fn respond(&mut self, request: Option<&Request>, answer: &Answer) -> bool {
        let len = answer.body.len() as u64;
        let mut bytes = head(request, answer, len).into_bytes();
        if request.is_none_or(|r| r.method != Method::Head) {
            // One write: the answer leaves in as few packets as it fits.
            bytes.extend_from_slice(&answer.body);
        }
        self.write(&bytes) && request.is_some_and(|r| !r.close)
    }

    /// Writes the head of `answer` for a body of `len` bytes, which the caller then writes;
    /// whether it was written.
    pub fn respond_head(&mut self, request: Option<&Request>, answer: &Answer, len: u64) -> bool {
        self.write(head(request, answer, len).as_bytes())
    }

    /// Writes `bytes`, waiting at most [`WRITE_TIMEOUT`] for the client to take them.
    pub fn write(&mut self, bytes: &[u8]) -> bool {
        self.stream.write_all(bytes).is_ok()
    }

    /// Closes the connection for both sides, so a thread blocked on it wakes.
    pub fn closer(&self) -> Option<TcpStream> {
        self.stream.try_clone().ok()
    }
}

/// An answer: status, headers and body.
pub struct Answer {
    pub status: u16,
    pub headers: Vec<(&'static str, String)>,
    pub body: Vec<u8>,
}

/// The status line and headers of `answer` for a body of `len` bytes, closing the connection
/// after it when the request asked (or could not be read).
fn head(request: Option<&Request>, answer: &Answer, len: u64) -> String {
    let close = request.is_none_or(|r| r.close);
    let mut head = format!(
        "HTTP/1.1 {} {}\r\nContent-Length: {len}\r\n",
        answer.status,
        reason(answer.status),
    );
    for (name, value) in &answer.headers {
        head.push_str(&format!("{name}: {value}\r\n"));
    }
    head.push_str(if close {
        "Connection: close\r\n\r\n"
    } else {
        "\r\n"
    });
    head
}

fn reason(status: u16) -> &'static str {
    match status {
        200 => "OK",
        400 => "Bad Request",
        403 => "Forbidden",
        404 => "Not Found",
        405 => "Method Not Allowed",
        413 => "Content Too Large",
        421 => "Misdirected Request",
        431 => "Request Header Fields Too Large",
        501 => "Not Implemented",
        503 => "Service Unavailable",
        _ => "Unknown",
    }
}

/// Where the head of a request ends (after its empty line), if it has arrived.
fn head_end(bytes: &[u8]) -> Option<usize> {
    let crlf = bytes
        .windows(4)
        .position(|w| w == b"\r\n\r\n")
        .map(|i| i + 4);
    let lf = bytes.windows(2).position(|w| w == b"\n\n").map(|i| i + 2);
    match (crlf, lf) {
        (Some(a), Some(b)) => Some(a.min(b)),
        (a, b) => a.or(b),
    }
}

/// The request line and headers of `head`.
pub fn parse_head(head: &[u8]) -> Result<Request, ReadError> {
    let text = std::str::from_utf8(head).map_err(|_| ReadError::Bad(400))?;
    let mut lines = text.lines().map(|l| l.strip_suffix('\r').unwrap_or(l));
    let mut parts = lines.next().unwrap_or("").split(' ');
    let (Some(method), Some(url), Some(version), None) =
        (parts.next(), parts.next(), parts.next(), parts.next())
    else {
        return Err(ReadError::Bad(400));
    };
    let http10 = match version {
        "HTTP/1.1" => false,
        "HTTP/1.0" => true,
        _ => return Err(ReadError::Bad(400)),
    };
    let method = match method {
        "GET" => Method::Get,
        "HEAD" => Method::Head,
        "POST" => Method::Post,
        m if !m.is_empty() && m.bytes().all(|b| b.is_ascii_uppercase()) => Method::Other,
        _ => return Err(ReadError::Bad(400)),
    };
    let mut headers = Vec::new();
    for line in lines.take_while(|l| !l.is_empty()) {
        let (name, value) = line.split_once(':').ok_or(ReadError::Bad(400))?;
        let token = |b: u8| b.is_ascii_alphanumeric() || b"!#$%&'*+-.^_`|~".contains(&b);
        if name.is_empty() || !name.bytes().all(token) {
            return Err(ReadError::Bad(400));
        }
        headers.push((name.to_string(), value.trim().to_string()));
    }
    let mut request = Request {
        method,
        url: url.to_string(),
        headers,
        close: false,
    };
    let connection = request.header("Connection").map(str::to_ascii_lowercase);
    request.close = match connection.as_deref() {
        Some(c) if c.contains("close") => true,
        Some(c) if c.contains("keep-alive") => false,
        _ => http10,
    };
    Ok(request)
}

/// Accepts connections until `stop` says so, each handed to `serve` on a thread of its own.
/// Accepting never fails for good: a full file table, a connection that cannot be set up or a
/// thread that cannot start drops that one connection, and the loop goes on.
pub fn accept_loop<S, F>(listener: &TcpListener, pool: &Arc<Pool>, stop: S, serve: F)
where
    S: Fn() -> bool,
    F: Fn(Connection) + Clone + Send + 'static,
{
    if listener.set_nonblocking(true).is_err() {
        // Blocking, the loop would not see the stop until the next client.
        return;
    }
    while !stop() {
        let stream = match listener.accept() {
            Ok((stream, _)) => stream,
            Err(e) if e.kind() == ErrorKind::WouldBlock => {
                std::thread::sleep(POLL);
                continue;
            }
            Err(_) => {
                // Out of files (or the client left first): let connections close, go on.
                std::thread::sleep(POLL);
                continue;
            }
        };
        let ready = stream.set_nonblocking(false).is_ok()
            && stream.set_write_timeout(Some(WRITE_TIMEOUT)).is_ok()
            && stream.set_nodelay(true).is_ok();
        if !ready || !pool.admit() {
            continue;
        }
        let connection = Connection {
            stream,
            id: pool.next_id.fetch_add(1, Ordering::Relaxed),
            pool: pool.clone(),
            buffered: Vec::new(),
        };
        let serve = serve.clone();
        // A thread that cannot start drops the connection (and gives its place back).
        let _ = std::thread::Builder::new()
            .name("anim-http".into())
            .stack_size(STACK)
            .spawn(move || serve(connection));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_head_is_read_as_browsers_and_tools_write_it() {
        let r = parse_head(b"GET /x?y=1 HTTP/1.1\r\nHost: a:1\r\nX-A:  b \r\n\r\n").unwrap();
        assert_eq!((r.method, r.url.as_str()), (Method::Get, "/x?y=1"));
        assert_eq!(r.header("host"), Some("a:1"));
        assert_eq!(r.header("x-a"), Some("b"));
        assert!(!r.close);
        let r = parse_head(b"HEAD / HTTP/1.0\n\n").unwrap();
        assert!(r.close && r.method == Method::Head);
        let r = parse_head(b"GET / HTTP/1.1\r\nConnection: Close\r\n\r\n").unwrap();
        assert!(r.close);
    }

    #[test]
    fn malformed_heads_are_bad_requests() {
        for bad in [
            &b"GET / HTTP/2\r\n\r\n"[..],
            b"GET /  HTTP/1.1\r\n\r\n",
            b"GET\r\n\r\n",
            b"get / HTTP/1.1\r\n\r\n",
            b"GET / HTTP/1.1\r\nno colon\r\n\r\n",
            b"GET / HTTP/1.1\r\nBad Name: x\r\n\r\n",
            b"GET / HTTP/1.1\r\n\xff: x\r\n\r\n",
            b"",
        ] {
            assert_eq!(
                parse_head(bad).err(),
                Some(ReadError::Bad(400)),
                "{:?}",
                String::from_utf8_lossy(bad)
            );
        }
    }

    #[test]
    fn the_head_ends_at_the_first_empty_line() {
        assert_eq!(head_end(b"GET / HTTP/1.1\r\n\r\nGET"), Some(18));
        assert_eq!(head_end(b"GET / HTTP/1.1\n\nx"), Some(16));
        assert_eq!(head_end(b"GET / HTTP/1.1\r\n"), None);
    }

    #[test]
    fn at_the_cap_the_longest_waiting_connection_makes_room() {
        let listener = TcpListener::bind("127.0.0.1:0").unwrap();
        let addr = listener.local_addr().unwrap();
        let pool = Arc::new(Pool::default());
        let mut clients = Vec::new();
        let mut served = Vec::new();
        for id in 0..MAX_CONNECTIONS as u64 {
            clients.push(TcpStream::connect(addr).unwrap());
            let (stream, _) = listener.accept().unwrap();
            assert!(pool.admit());
            pool.set_waiting(id, &stream, id != 0);
            served.push(stream);
        }
        assert_eq!(pool.lock().count, MAX_CONNECTIONS);
        // The first is busy (not waiting): the second, the oldest waiting, is closed.
        assert!(pool.admit());
        let mut byte = [0u8; 1];
        let mut second = &served[1];
        assert_eq!(second.read(&mut byte).unwrap(), 0);
        for (id, _) in served.iter().enumerate().skip(2) {
            pool.set_waiting(id as u64, &served[id], false);
        }
        pool.set_waiting(0, &served[0], false);
        // Nobody left waiting: the next connection is refused until one has left.
        assert!(!pool.admit());
        pool.leave(1);
        assert!(!pool.admit());
        pool.leave(2);
        assert!(pool.admit());
    }
}
