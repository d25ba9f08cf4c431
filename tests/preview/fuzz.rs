//! A fuzz driver for the preview's HTTP surface (stable Rust): one `anim preview` on a small
//! scene gets random requests over random connection patterns (requests from the routes
//! mutated, random bytes, heads cut short, pipelined bursts read or left unread, connections
//! left open mid-head, bodies that lie about their length) and, every few hundred, the page
//! is asked for as a browser would: it must answer 200 within a second every time, and the
//! preview must end cleanly on Ctrl-C at the end. Every answer must be HTTP/1.1 with a status
//! the server sends. See FUZZING.md; `scripts/fuzz.sh --http` runs it.
//!
//! Settings from the environment: `HTTP_FUZZ_REQUESTS` (default 300 000), `HTTP_FUZZ_SEED`
//! (1), `HTTP_FUZZ_CLIENTS` (4 threads at once, client `i` drawing from seed + i).
//! Deterministic in what each client sends (`SplitMix64`), not in timing.

use crate::session::Preview;
use anim_core::util::SplitMix64;
use std::io::{Read, Write};
use std::net::TcpStream;
use std::time::{Duration, Instant};

/// Requests a browser and the page's script send, the material of the mutations.
const REQUESTS: &[&str] = &[
    "GET / HTTP/1.1\r\nHost: {host}\r\n\r\n",
    "GET /index.html HTTP/1.1\r\nHost: {host}\r\nAccept: text/html\r\n\r\n",
    "GET /app.js HTTP/1.1\r\nHost: {host}\r\n\r\n",
    "HEAD /style.css HTTP/1.1\r\nHost: {host}\r\n\r\n",
    "GET /api/state HTTP/1.1\r\nHost: {host}\r\nConnection: keep-alive\r\n\r\n",
    "GET /frame/0.png?v=3 HTTP/1.1\r\nHost: {host}\r\n\r\n",
    "GET /frame/99999999999999999999.png HTTP/1.1\r\nHost: {host}\r\n\r\n",
    "POST /api/focus?frame=0 HTTP/1.1\r\nHost: {host}\r\nOrigin: http://{host}\r\nContent-Length: 0\r\n\r\n",
    "POST /api/focus?frame=-1 HTTP/1.1\r\nHost: {host}\r\nContent-Length: 5\r\n\r\nhello",
    "GET /export/preview.mp4 HTTP/1.0\r\nHost: {host}\r\n\r\n",
    "GET /../../etc/passwd HTTP/1.1\r\nHost: {host}\r\n\r\n",
    "GET /%2e%2e/x HTTP/1.1\r\nHost: {host}\r\n\r\n",
    "GET http://evil/ HTTP/1.1\r\nHost: evil.example\r\n\r\n",
    "POST /api/export HTTP/1.1\r\nHost: {host}\r\nOrigin: http://evil.example\r\n\r\n",
    "GET / HTTP/1.1\r\nHost: {host}\r\nTransfer-Encoding: chunked\r\n\r\n0\r\n\r\n",
    "GET / HTTP/1.1\r\nHost: {host}\r\nContent-Length: 99999999999999999999\r\n\r\n",
    "GET /events HTTP/1.1\r\nHost: {host}\r\n\r\n",
];

/// Bytes that parsers get wrong, written in place of others.
const SPECIAL: &[u8] = b"\0\r\n :/%?#.\\\x7f\xff\t";

/// Statuses the server answers with.
const STATUSES: &[u16] = &[200, 400, 403, 404, 405, 413, 421, 431, 501, 503];

#[derive(Default, Debug)]
struct Tally {
    requests: u64,
    connections: u64,
    answers: u64,
    checks: u64,
    slowest_check: Duration,
}

/// `request` with 0 to 4 mutations.
fn mutate(rng: &mut SplitMix64, request: &[u8]) -> Vec<u8> {
    let mut r = request.to_vec();
    for _ in 0..rng.next_u64() % 5 {
        let at = (rng.next_u64() as usize) % (r.len() + 1);
        match rng.next_u64() % 7 {
            0 if at < r.len() => r[at] ^= 1 << (rng.next_u64() % 8),
            1 if at < r.len() => r[at] = SPECIAL[(rng.next_u64() as usize) % SPECIAL.len()],
            2 => r.insert(at, SPECIAL[(rng.next_u64() as usize) % SPECIAL.len()]),
            3 => r.truncate(at),
            4 => {
                let n = 1 + (rng.next_u64() % 20_000) as usize;
                r.splice(at..at, std::iter::repeat_n(b'a', n));
            }
            5 => {
                let header = format!("X-{}: {}\r\n", rng.next_u64(), "v".repeat(100));
                let line = r.windows(2).position(|w| w == b"\r\n").map_or(0, |i| i + 2);
                r.splice(
                    line..line,
                    header
                        .repeat(1 + (rng.next_u64() % 300) as usize)
                        .into_bytes(),
                );
            }
            _ if at < r.len() => {
                r.remove(at);
            }
            _ => {}
        }
    }
    r
}

/// Reads what the server answers until it closes or is quiet for `wait`; checks each
/// answer's status line.
fn read_answers(stream: &mut TcpStream, wait: Duration) -> u64 {
    let _ = stream.set_read_timeout(Some(wait));
    let mut got = Vec::new();
    let mut chunk = [0u8; 16 << 10];
    for _ in 0..64 {
        match stream.read(&mut chunk) {
            Ok(0) | Err(_) => break,
            Ok(n) => got.extend_from_slice(&chunk[..n]),
        }
        // An event stream never ends: its first event is enough.
        let stream_began = got.windows(17).any(|w| w == b"text/event-stream");
        if stream_began && got.windows(6).any(|w| w == b"data: ") {
            break;
        }
    }
    let text = String::from_utf8_lossy(&got);
    let mut answers = 0;
    for (i, _) in text.match_indices("HTTP/1.1 ") {
        let status: u16 = text[i + 9..]
            .get(..3)
            .and_then(|s| s.parse().ok())
            .unwrap_or(0);
        // A body (a script, a state) may hold the words too; a status line starts a line.
        if i == 0 || text[..i].ends_with('\n') {
            assert!(
                STATUSES.contains(&status),
                "status {status} in {:?}",
                &text[i..]
            );
            answers += 1;
        }
    }
    answers
}

/// One connection of a random pattern; the requests it sent.
fn one_connection(rng: &mut SplitMix64, port: u16, held: &mut Vec<TcpStream>) -> (u64, u64) {
    let host = format!("127.0.0.1:{port}");
    let Ok(mut stream) = TcpStream::connect(("127.0.0.1", port)) else {
        return (0, 0);
    };
    let _ = stream.set_write_timeout(Some(Duration::from_secs(2)));
    let pick = |rng: &mut SplitMix64| {
        let base = REQUESTS[(rng.next_u64() as usize) % REQUESTS.len()].replace("{host}", &host);
        mutate(rng, base.as_bytes())
    };
    match rng.next_u64() % 8 {
        // Pipelined requests, answers read.
        0..=3 => {
            let n = 1 + rng.next_u64() % 8;
            let burst: Vec<u8> = (0..n).flat_map(|_| pick(rng)).collect();
            let _ = stream.write_all(&burst);
            // The end of the requests: the server answers what came, then closes.
            let _ = stream.shutdown(std::net::Shutdown::Write);
            (n, read_answers(&mut stream, Duration::from_millis(300)))
        }
        // Random bytes.
        4 => {
            let n = (rng.next_u64() % 4096) as usize;
            let bytes: Vec<u8> = (0..n).map(|_| rng.next_u64() as u8).collect();
            let _ = stream.write_all(&bytes);
            let _ = stream.shutdown(std::net::Shutdown::Write);
            (1, read_answers(&mut stream, Duration::from_millis(100)))
        }
        // Pipelined, never read: closed with the answers unread.
        5 => {
            let n = 1 + rng.next_u64() % 64;
            let burst: Vec<u8> = (0..n).flat_map(|_| pick(rng)).collect();
            let _ = stream.write_all(&burst);
            (n, 0)
        }
        // A head cut short, left open (up to a few hundred at once) or closed.
        6 => {
            let request = pick(rng);
            let cut = (rng.next_u64() as usize) % (request.len() + 1);
            let _ = stream.write_all(&request[..cut]);
            if held.len() < 300 {
                held.push(stream);
            } else {
                held.swap_remove((rng.next_u64() as usize) % held.len());
            }
            (1, 0)
        }
        // Connected and closed without a byte.
        _ => (0, 0),
    }
}

/// The page, as a browser asks for it: 200 within a second.
fn page_is_served(preview: &Preview, tally: &mut Tally) {
    let start = Instant::now();
    let (status, body) = preview.get("/");
    let took = start.elapsed();
    assert_eq!(status, 200, "after {} requests", tally.requests);
    assert!(String::from_utf8_lossy(&body).contains("<html"));
    assert!(took < Duration::from_secs(1), "the page took {took:?}");
    tally.checks += 1;
    tally.slowest_check = tally.slowest_check.max(took);
}

/// `requests` requests from `clients` threads at once (client `i` draws from seed
/// `seed + i`), the page checked every 500 requests of each client.
fn run(requests: u64, seed: u64, clients: u64) -> Tally {
    let mut preview = Preview::start_scene();
    let tallies: Vec<Tally> = std::thread::scope(|scope| {
        let preview = &preview;
        let workers: Vec<_> = (0..clients)
            .map(|i| scope.spawn(move || client(preview, requests / clients, seed + i)))
            .collect();
        workers.into_iter().map(|w| w.join().unwrap()).collect()
    });
    let mut tally = Tally::default();
    for t in tallies {
        tally.requests += t.requests;
        tally.connections += t.connections;
        tally.answers += t.answers;
        tally.checks += t.checks;
        tally.slowest_check = tally.slowest_check.max(t.slowest_check);
    }
    page_is_served(&preview, &mut tally);
    assert!(preview.stop(), "the preview did not end cleanly");
    tally
}

fn client(preview: &Preview, requests: u64, seed: u64) -> Tally {
    let mut rng = SplitMix64::new(seed);
    let mut tally = Tally::default();
    let mut held = Vec::new();
    let mut next_check = 0;
    while tally.requests < requests {
        let (sent, answers) = one_connection(&mut rng, preview.port, &mut held);
        tally.requests += sent;
        tally.answers += answers;
        tally.connections += 1;
        if tally.requests >= next_check {
            page_is_served(preview, &mut tally);
            next_check = tally.requests + 500;
        }
    }
    tally
}

/// The fuzz run proper (`scripts/fuzz.sh --http`).
#[test]
#[ignore = "long; run with scripts/fuzz.sh --http"]
fn http_fuzz() {
    let number = |name: &str, default: u64| {
        std::env::var(name)
            .ok()
            .and_then(|v| v.parse().ok())
            .unwrap_or(default)
    };
    let start = Instant::now();
    let tally = run(
        number("HTTP_FUZZ_REQUESTS", 300_000),
        number("HTTP_FUZZ_SEED", 1),
        number("HTTP_FUZZ_CLIENTS", 4).max(1),
    );
    let secs = start.elapsed().as_secs_f64();
    eprintln!(
        "http fuzz: {} requests over {} connections in {secs:.0} s, {} answers read, {} page checks (slowest {:?})",
        tally.requests, tally.connections, tally.answers, tally.checks, tally.slowest_check
    );
}

/// A short run on every test pass.
#[test]
fn http_fuzz_smoke() {
    let tally = run(2_000, 7, 2);
    assert!(tally.answers > 0 && tally.checks > 2, "{tally:?}");
}

#[test]
fn mutations_stay_deterministic() {
    let request = b"GET / HTTP/1.1\r\nHost: a\r\n\r\n";
    let a: Vec<Vec<u8>> = {
        let mut rng = SplitMix64::new(3);
        (0..20).map(|_| mutate(&mut rng, request)).collect()
    };
    let mut rng = SplitMix64::new(3);
    let b: Vec<Vec<u8>> = (0..20).map(|_| mutate(&mut rng, request)).collect();
    assert_eq!(a, b);
    assert!(a.iter().any(|m| m.as_slice() != request));
}
