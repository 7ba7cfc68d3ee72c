//! `cargo xtask fetch-data` end to end, offline: the real binary against a small HTTP/1.1 server
//! on 127.0.0.1 (std::net only) that serves test files, honours `Range`, and can ignore it or cut
//! a response midway. Every test has its own server, manifest directory and data root.

use sha2::{Digest, Sha256};
use std::collections::HashMap;
use std::io::{BufRead, BufReader, Write};
use std::net::{TcpListener, TcpStream};
use std::path::{Path, PathBuf};
use std::process::Output;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::time::Duration;

/// How the server answers one path.
#[derive(Clone, Copy)]
enum Mode {
    /// 200, or 206 for `Range: bytes=N-`.
    Normal,
    /// Always 200 with the whole body.
    IgnoreRange,
    /// The first `n` responses announce the full length but send only `cut` bytes, then close.
    CutFirst { n: usize, cut: usize },
}

#[derive(Default)]
struct State {
    files: HashMap<String, (Vec<u8>, Mode)>,
    /// (path, Range header) of every request, in order.
    log: Vec<(String, Option<String>)>,
}

struct Server {
    port: u16,
    state: Arc<Mutex<State>>,
    stop: Arc<AtomicBool>,
    thread: Option<std::thread::JoinHandle<()>>,
}

impl Server {
    fn start() -> Server {
        let listener = TcpListener::bind("127.0.0.1:0").unwrap();
        let port = listener.local_addr().unwrap().port();
        let state = Arc::new(Mutex::new(State::default()));
        let stop = Arc::new(AtomicBool::new(false));
        let (s, st) = (state.clone(), stop.clone());
        let thread = std::thread::spawn(move || {
            // Bounded: a test makes a handful of requests.
            for conn in listener.incoming().take(200) {
                if st.load(Ordering::SeqCst) {
                    break;
                }
                if let Ok(c) = conn {
                    let _ = serve(c, &s);
                }
            }
        });
        Server { port, state, stop, thread: Some(thread) }
    }

    fn add(&self, path: &str, body: &[u8], mode: Mode) {
        self.state.lock().unwrap().files.insert(path.into(), (body.to_vec(), mode));
    }

    fn url(&self, path: &str) -> String {
        format!("http://127.0.0.1:{}{path}", self.port)
    }

    fn log(&self) -> Vec<(String, Option<String>)> {
        self.state.lock().unwrap().log.clone()
    }
}

impl Drop for Server {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::SeqCst);
        let _ = TcpStream::connect(("127.0.0.1", self.port));
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}

fn serve(mut c: TcpStream, state: &Mutex<State>) -> std::io::Result<()> {
    c.set_read_timeout(Some(Duration::from_secs(5)))?;
    let mut reader = BufReader::new(c.try_clone()?);
    let mut line = String::new();
    reader.read_line(&mut line)?;
    let path = line.split_whitespace().nth(1).unwrap_or("/").to_string();
    let mut range = None;
    loop {
        let mut h = String::new();
        if reader.read_line(&mut h)? == 0 || h.trim().is_empty() {
            break;
        }
        if let Some((k, v)) = h.split_once(':')
            && k.trim().eq_ignore_ascii_case("range")
        {
            range = Some(v.trim().to_string());
        }
    }
    let found = {
        let mut s = state.lock().unwrap();
        s.log.push((path.clone(), range.clone()));
        let found = s.files.get(&path).cloned();
        if let Some((_, Mode::CutFirst { n, cut })) = found
            && n > 0
        {
            let body = s.files[&path].0.clone();
            s.files.insert(path.clone(), (body, Mode::CutFirst { n: n - 1, cut }));
        }
        found
    };
    let Some((body, mode)) = found else {
        return c.write_all(
            b"HTTP/1.1 404 Not Found\r\nContent-Length: 0\r\nConnection: close\r\n\r\n",
        );
    };
    let start = match (mode, &range) {
        (Mode::IgnoreRange, _) | (_, None) => None,
        (_, Some(r)) => r.strip_prefix("bytes=").and_then(|r| r.trim_end_matches('-').parse().ok()),
    };
    let len = body.len();
    let (head, slice) = match start {
        Some(s) if s >= len => {
            let h = format!(
                "HTTP/1.1 416 Range Not Satisfiable\r\nContent-Range: bytes */{len}\r\n\
                 Content-Length: 0\r\nConnection: close\r\n\r\n"
            );
            (h, &body[0..0])
        }
        Some(s) => {
            let h = format!(
                "HTTP/1.1 206 Partial Content\r\nContent-Range: bytes {s}-{}/{len}\r\n\
                 Content-Length: {}\r\nConnection: close\r\n\r\n",
                len - 1,
                len - s
            );
            (h, &body[s..])
        }
        None => {
            let h =
                format!("HTTP/1.1 200 OK\r\nContent-Length: {len}\r\nConnection: close\r\n\r\n");
            (h, &body[..])
        }
    };
    c.write_all(head.as_bytes())?;
    match mode {
        Mode::CutFirst { n, cut } if n > 0 => c.write_all(&slice[..cut.min(slice.len())])?,
        _ => c.write_all(slice)?,
    }
    c.flush()?;
    c.shutdown(std::net::Shutdown::Both)
}

/// A per-test scratch directory with `manifests/` and `data/`, removed on drop.
struct Scratch(
    PathBuf,
    #[expect(dead_code, reason = "held for its Drop, which removes the directory")]
    test_support::TempDir,
);

impl Scratch {
    fn new(tag: &str) -> Scratch {
        let tmp = test_support::TempDir::new(&format!("fetch-{tag}"));
        std::fs::create_dir_all(tmp.0.join("manifests")).unwrap();
        Scratch(tmp.0.clone(), tmp)
    }
    fn data(&self) -> PathBuf {
        self.0.join("data")
    }
    /// Writes manifest `t` with the given `[[file]]` blocks.
    fn manifest(&self, files: &str) {
        let text = format!(
            "[dataset]\nname = \"t\"\ntitle = \"Test\"\npage = \"http://127.0.0.1/\"\n\
             licence = \"CC0\"\ncitation = \"none\"\n\n{files}"
        );
        std::fs::write(self.0.join("manifests/t.toml"), text).unwrap();
    }
    fn run(&self, args: &[&str]) -> Output {
        let mut cmd = std::process::Command::new(env!("CARGO_BIN_EXE_xtask"));
        cmd.arg("fetch-data").arg("--manifests").arg(self.0.join("manifests"));
        cmd.arg("--dest").arg(self.data()).args(args).env_remove("NEURAL_BRDF_DATA");
        cmd.output().unwrap()
    }
}

fn entry(name: &str, url: &str, sha: &str, size: Option<usize>) -> String {
    let size = size.map_or(String::new(), |s| format!("size = {s}\n"));
    format!(
        "[[file]]\nname = \"{name}\"\nurl = \"{url}\"\nsha256 = \"{sha}\"\n{size}dest = \"d/{name}.bin\"\n\n"
    )
}

fn sha(b: &[u8]) -> String {
    Sha256::digest(b).iter().map(|x| format!("{x:02x}")).collect()
}

/// 300 kB of deterministic, non-repeating bytes.
fn payload() -> Vec<u8> {
    let mut x = 0x9e3779b97f4a7c15u64;
    (0..300_000)
        .map(|_| {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            x as u8
        })
        .collect()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn ok(o: &Output) {
    assert!(o.status.success(), "fetch-data failed:\n{}", stderr(o));
}

fn failed(o: &Output) -> String {
    assert!(!o.status.success(), "fetch-data should have failed:\n{}", stderr(o));
    stderr(o)
}

fn part(p: &Path) -> PathBuf {
    PathBuf::from(format!("{}.part", p.display()))
}

#[test]
fn full_download_verifies_then_is_skipped() {
    let (srv, s, body) = (Server::start(), Scratch::new("full"), payload());
    srv.add("/a.bin", &body, Mode::Normal);
    s.manifest(&entry("a", &srv.url("/a.bin"), &sha(&body), Some(body.len())));
    let o = s.run(&["t"]);
    ok(&o);
    let out = s.data().join("d/a.bin");
    assert_eq!(std::fs::read(&out).unwrap(), body);
    assert!(!part(&out).exists());
    assert!(stderr(&o).contains("sha256 verified"), "{}", stderr(&o));
    // Second run: the verified file is kept without a request.
    let o = s.run(&["t"]);
    ok(&o);
    assert!(stderr(&o).contains("present, sha256 verified"), "{}", stderr(&o));
    assert_eq!(srv.log().len(), 1);
}

#[test]
fn truncated_part_resumes_with_range() {
    let (srv, s, body) = (Server::start(), Scratch::new("resume"), payload());
    srv.add("/a.bin", &body, Mode::Normal);
    s.manifest(&entry("a", &srv.url("/a.bin"), &sha(&body), Some(body.len())));
    let out = s.data().join("d/a.bin");
    std::fs::create_dir_all(out.parent().unwrap()).unwrap();
    std::fs::write(part(&out), &body[..123_456]).unwrap();
    let o = s.run(&["t"]);
    ok(&o);
    assert_eq!(std::fs::read(&out).unwrap(), body);
    assert_eq!(srv.log(), [("/a.bin".to_string(), Some("bytes=123456-".to_string()))]);
    assert!(stderr(&o).contains("resumed at byte 123456"), "{}", stderr(&o));
}

#[test]
fn connection_cut_midway_is_resumed_in_the_same_run() {
    let (srv, s, body) = (Server::start(), Scratch::new("cut"), payload());
    srv.add("/a.bin", &body, Mode::CutFirst { n: 2, cut: 50_000 });
    s.manifest(&entry("a", &srv.url("/a.bin"), &sha(&body), None));
    let o = s.run(&["t"]);
    ok(&o);
    assert_eq!(std::fs::read(s.data().join("d/a.bin")).unwrap(), body);
    let ranges: Vec<Option<String>> = srv.log().into_iter().map(|(_, r)| r).collect();
    assert_eq!(
        ranges,
        [None, Some("bytes=50000-".into()), Some("bytes=100000-".into())],
        "{}",
        stderr(&o)
    );
}

#[test]
fn server_ignoring_range_restarts_cleanly() {
    let (srv, s, body) = (Server::start(), Scratch::new("norange"), payload());
    srv.add("/a.bin", &body, Mode::IgnoreRange);
    s.manifest(&entry("a", &srv.url("/a.bin"), &sha(&body), Some(body.len())));
    let out = s.data().join("d/a.bin");
    std::fs::create_dir_all(out.parent().unwrap()).unwrap();
    std::fs::write(part(&out), &body[..1000]).unwrap();
    let o = s.run(&["t"]);
    ok(&o);
    assert_eq!(std::fs::read(&out).unwrap(), body);
    assert!(stderr(&o).contains("ignored the Range request"), "{}", stderr(&o));
}

#[test]
fn checksum_mismatch_is_a_clear_error_and_leaves_nothing() {
    let (srv, s, body) = (Server::start(), Scratch::new("mismatch"), payload());
    srv.add("/a.bin", &body, Mode::Normal);
    let wrong = sha(b"something else");
    s.manifest(&entry("a", &srv.url("/a.bin"), &wrong, None));
    let err = failed(&s.run(&["t"]));
    assert!(
        err.contains("sha256 mismatch") && err.contains(&wrong) && err.contains(&sha(&body)),
        "{err}"
    );
    assert!(err.contains(&srv.url("/a.bin")), "{err}");
    let out = s.data().join("d/a.bin");
    assert!(!out.exists() && !part(&out).exists());
}

#[test]
fn corrupt_part_is_downloaded_again_whole() {
    let (srv, s, body) = (Server::start(), Scratch::new("corrupt"), payload());
    srv.add("/a.bin", &body, Mode::Normal);
    s.manifest(&entry("a", &srv.url("/a.bin"), &sha(&body), Some(body.len())));
    let out = s.data().join("d/a.bin");
    std::fs::create_dir_all(out.parent().unwrap()).unwrap();
    std::fs::write(part(&out), vec![0u8; 1000]).unwrap();
    ok(&s.run(&["t"]));
    assert_eq!(std::fs::read(&out).unwrap(), body);
    assert_eq!(srv.log().len(), 2);
}

#[test]
fn http_404_and_refused_connection_are_clear_errors() {
    let (srv, s) = (Server::start(), Scratch::new("404"));
    // A port nothing listens on: bind one, note it, close it.
    let closed = TcpListener::bind("127.0.0.1:0").unwrap().local_addr().unwrap().port();
    let refused = format!("http://127.0.0.1:{closed}/b.bin");
    s.manifest(
        &(entry("a", &srv.url("/missing.bin"), &sha(b"x"), None)
            + &entry("b", &refused, &sha(b"x"), None)),
    );
    let err = failed(&s.run(&["t"]));
    assert!(err.contains("HTTP 404") && err.contains(&srv.url("/missing.bin")), "{err}");
    assert!(err.contains(&refused) && err.to_lowercase().contains("connect"), "{err}");
    assert!(err.contains("2 of 2 file(s)"), "{err}");
    assert!(!s.data().join("d/a.bin").exists());
}

#[test]
fn unknown_checksum_needs_the_flag_then_is_locked() {
    let (srv, s, body) = (Server::start(), Scratch::new("unknown"), payload());
    srv.add("/a.bin", &body, Mode::Normal);
    s.manifest(&entry("a", &srv.url("/a.bin"), "unknown", None));
    let out = s.data().join("d/a.bin");
    let err = failed(&s.run(&["t"]));
    assert!(err.contains("no published sha256") && err.contains(&sha(&body)), "{err}");
    assert!(err.contains("--allow-unverified"), "{err}");
    assert!(!out.exists() && part(&out).exists());
    // With the flag: the kept part is complete (416 for the next byte), accepted and recorded.
    let o = s.run(&["t", "--allow-unverified"]);
    ok(&o);
    assert!(stderr(&o).contains("UNVERIFIED"), "{}", stderr(&o));
    assert_eq!(std::fs::read(&out).unwrap(), body);
    let lock = std::fs::read_to_string(s.data().join("fetch-lock.toml")).unwrap();
    assert!(lock.contains(&sha(&body)) && lock.contains("d/a.bin"), "{lock}");
    assert_eq!(srv.log().len(), 2);
    // Later runs verify against the lock, without the flag; a changed file is caught.
    let o = s.run(&["t"]);
    ok(&o);
    assert!(stderr(&o).contains("local lock"), "{}", stderr(&o));
    std::fs::write(&out, b"tampered").unwrap();
    srv.add("/a.bin", b"a different upstream file", Mode::Normal);
    let err = failed(&s.run(&["t"]));
    assert!(err.contains("sha256 mismatch") && err.contains("local lock"), "{err}");
}

#[test]
fn published_prefix_is_checked() {
    let (srv, s, body) = (Server::start(), Scratch::new("prefix"), payload());
    srv.add("/a.bin", &body, Mode::Normal);
    let good = entry("a", &srv.url("/a.bin"), "unknown", None);
    s.manifest(
        &format!("{good}sha256_prefix = \"{}\"\n", &sha(b"other")[..8])
            .replace("dest = \"d/a.bin\"\n\nsha256_prefix", "dest = \"d/a.bin\"\nsha256_prefix"),
    );
    let err = failed(&s.run(&["t", "--allow-unverified"]));
    assert!(err.contains("published prefix"), "{err}");
    assert!(!s.data().join("d/a.bin").exists());
}

#[test]
fn zip_is_unpacked_once_and_traversal_is_refused() {
    let (srv, s) = (Server::start(), Scratch::new("zip"));
    let zip_of = |names: &[&str]| {
        let mut w = zip::ZipWriter::new(std::io::Cursor::new(Vec::new()));
        for n in names {
            w.start_file(*n, zip::write::FileOptions::default()).unwrap();
            w.write_all(format!("content of {n}").as_bytes()).unwrap();
        }
        w.finish().unwrap().into_inner()
    };
    let good = zip_of(&["top/x.txt", "top/sub/y.txt"]);
    let evil = zip_of(&["../escape.txt"]);
    srv.add("/good.zip", &good, Mode::Normal);
    srv.add("/evil.zip", &evil, Mode::Normal);
    let unpack = |name: &str, url: &str, bytes: &[u8]| {
        entry(name, url, &sha(bytes), None)
            + &format!("unpack = {{ format = \"zip\", into = \"u/{name}\" }}\n\n")
    };
    let files = unpack("good", &srv.url("/good.zip"), &good)
        + &unpack("evil", &srv.url("/evil.zip"), &evil);
    s.manifest(
        &files
            .replace("dest = \"d/good.bin\"\n\nunpack", "dest = \"d/good.bin\"\nunpack")
            .replace("dest = \"d/evil.bin\"\n\nunpack", "dest = \"d/evil.bin\"\nunpack"),
    );
    let o = s.run(&["t", "--only", "good"]);
    ok(&o);
    let y = s.data().join("u/good/top/sub/y.txt");
    assert_eq!(std::fs::read_to_string(&y).unwrap(), "content of top/sub/y.txt");
    let o = s.run(&["t", "--only", "good"]);
    ok(&o);
    assert!(stderr(&o).contains("already unpacked"), "{}", stderr(&o));
    let err = failed(&s.run(&["t", "--only", "evil"]));
    assert!(err.contains("outside the target directory"), "{err}");
    for left in ["u/escape.txt", "u/evil", "u/evil.unpacking"] {
        assert!(!s.data().join(left).exists(), "{left}");
    }
}

#[test]
fn manual_entry_explains_what_to_do_and_unknown_entry_is_named() {
    let s = Scratch::new("manual");
    s.manifest("[[file]]\nname = \"m\"\nsha256 = \"unknown\"\ndest = \"d/m.zip\"\n");
    let err = failed(&s.run(&["t"]));
    assert!(err.contains("by hand") && err.contains("http://127.0.0.1/"), "{err}");
    let err = failed(&s.run(&["t", "--only", "nope"]));
    assert!(err.contains("`nope`") && err.contains("entries: m"), "{err}");
    let err = failed(&s.run(&["nothere"]));
    assert!(err.contains("no manifest named `nothere`") && err.contains("available: t"), "{err}");
    let o = s.run(&["--list"]);
    ok(&o);
    assert!(String::from_utf8_lossy(&o.stdout).contains("d/m.zip"));
}
