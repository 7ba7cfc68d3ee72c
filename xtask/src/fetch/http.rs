//! One HTTP(S) download into `<file>.part`: resumes an existing part with a `Range` request,
//! restarts when the server ignores it, retries transfers cut midway (resuming each time), hashes
//! while it writes, and shows a byte bar. Errors name the URL or the file and the fault.

use super::progress::{hash_into, hex};
use anyhow::{Context, Result, anyhow};
use sha2::{Digest, Sha256};
use std::fs::OpenOptions;
use std::io::{Read, Seek, SeekFrom, Write};
use std::path::Path;
use std::time::Duration;

/// Attempts per file (the first one included) before a transfer error is final.
const ATTEMPTS: u32 = 4;

/// A finished download.
#[derive(Debug)]
pub struct Fetched {
    /// sha256 of the whole part file (hex).
    pub sha256: String,
    /// Its length in bytes.
    pub len: u64,
    /// Bytes that were already there and kept (0 for a fresh download).
    pub resumed_from: u64,
}

/// Why one attempt stopped.
enum Fault {
    /// Worth another attempt (connection cut, 5xx, a part the server would not resume).
    Retry(anyhow::Error),
    /// Final (4xx, unreachable host, disk error).
    Fatal(anyhow::Error),
}

/// Downloads `url` into `part` (resuming what is there), `expected_size` bytes if known.
pub fn download(
    url: &str,
    part: &Path,
    expected_size: Option<u64>,
    label: &str,
) -> Result<Fetched> {
    check_scheme(url)?;
    let agent = ureq::AgentBuilder::new()
        .timeout_connect(Duration::from_secs(30))
        .timeout_read(Duration::from_secs(60))
        .redirects(8)
        .user_agent(concat!("neural-brdfs-xtask/", env!("CARGO_PKG_VERSION")))
        .build();
    let mut last = None;
    for attempt in 1..=ATTEMPTS {
        match attempt_once(&agent, url, part, expected_size, label) {
            Ok(f) => return Ok(f),
            Err(Fault::Fatal(e)) => return Err(e),
            Err(Fault::Retry(e)) => {
                if attempt < ATTEMPTS {
                    eprintln!("    {e:#}; retrying ({attempt}/{})", ATTEMPTS - 1);
                    std::thread::sleep(Duration::from_millis(300 * u64::from(attempt)));
                }
                last = Some(e);
            }
        }
    }
    let e = last.unwrap_or_else(|| anyhow!("no attempt was made"));
    Err(e.context(format!("giving up on {url} after {ATTEMPTS} attempts")))
}

#[cfg(feature = "tls")]
fn check_scheme(_url: &str) -> Result<()> {
    Ok(())
}

#[cfg(not(feature = "tls"))]
fn check_scheme(url: &str) -> Result<()> {
    anyhow::ensure!(
        !url.starts_with("https://"),
        "{url}: this xtask was built without its `tls` feature and cannot fetch https URLs \
         (build it with default features)"
    );
    Ok(())
}

/// One download attempt of `url` into the part file `part`, resuming from its length.
fn attempt_once(
    agent: &ureq::Agent,
    url: &str,
    part: &Path,
    expected_size: Option<u64>,
    label: &str,
) -> Result<Fetched, Fault> {
    let (offset, mut hasher) = resume_point(part, expected_size, label)?;
    let complete = |hasher: Sha256| Fetched {
        sha256: hex(&hasher.finalize()),
        len: offset,
        resumed_from: offset,
    };
    if offset > 0 && expected_size == Some(offset) {
        return Ok(complete(hasher));
    }
    let Some(response) = send(agent, url, offset, part)? else {
        return Ok(complete(hasher));
    };
    let (start, total) = body_range(&response, url, offset, part)?;
    if start == 0 && offset > 0 {
        eprintln!("    {url}: the server ignored the Range request; downloading it whole");
        hasher = Sha256::new();
    }
    let len =
        stream_to_part(response, (url, part), start, total.or(expected_size), &mut hasher, label)?;
    if let Some(t) = total
        && t != len
    {
        return Err(Fault::Retry(anyhow!("GET {url}: got {len} bytes of {t}")));
    }
    Ok(Fetched { sha256: hex(&hasher.finalize()), len, resumed_from: start })
}

/// An error on the part file: fatal (disk trouble is not cured by trying again).
fn disk_fault(what: &str, part: &Path) -> impl Fn(std::io::Error) -> Fault {
    let msg = format!("{what} {}", part.display());
    move |e: std::io::Error| Fault::Fatal(anyhow!(e).context(msg.clone()))
}

/// Where the attempt starts: the part file's length (0 when there is none, or when it is
/// longer than the expected size) and the hash of the bytes already there.
fn resume_point(
    part: &Path,
    expected_size: Option<u64>,
    label: &str,
) -> Result<(u64, Sha256), Fault> {
    let mut offset = match std::fs::metadata(part) {
        Ok(m) => m.len(),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => 0,
        Err(e) => return Err(disk_fault("reading", part)(e)),
    };
    if expected_size.is_some_and(|s| offset > s) {
        truncate(part).map_err(Fault::Fatal)?;
        offset = 0;
    }
    let mut hasher = Sha256::new();
    if offset > 0 {
        hash_into(&mut hasher, part, Some(offset), &format!("{label} (partial)"))
            .map_err(Fault::Fatal)?;
    }
    Ok((offset, hasher))
}

/// The GET request for the bytes from `offset` on: the response, or `None` when the server
/// says nothing is left past a complete part. Server errors and broken connections are
/// retried, other failures are fatal.
fn send(
    agent: &ureq::Agent,
    url: &str,
    offset: u64,
    part: &Path,
) -> Result<Option<ureq::Response>, Fault> {
    // Bytes as stored: a compressed transfer would make byte offsets (resume) meaningless.
    let mut request = agent.get(url).set("Accept-Encoding", "identity");
    if offset > 0 {
        request = request.set("Range", &format!("bytes={offset}-"));
    }
    match request.call() {
        Ok(r) => Ok(Some(r)),
        Err(ureq::Error::Status(416, r)) if offset > 0 => {
            // Nothing left past `offset`: the part is complete if the server's total says so.
            if content_range(r.header("Content-Range")).is_some_and(|(_, t)| t == Some(offset)) {
                return Ok(None);
            }
            truncate(part).map_err(Fault::Fatal)?;
            Err(Fault::Retry(anyhow!(
                "GET {url}: HTTP 416 for a part of {offset} bytes; starting again from 0"
            )))
        }
        Err(ureq::Error::Status(code, r)) => {
            let e = anyhow!("GET {url}: HTTP {code} {}", r.status_text());
            Err(if code >= 500 || code == 408 || code == 429 {
                Fault::Retry(e)
            } else {
                Fault::Fatal(e)
            })
        }
        Err(ureq::Error::Transport(t)) => {
            // ureq's message starts with the URL already.
            let msg = t.to_string();
            let msg = msg.strip_prefix(&format!("{url}: ")).unwrap_or(&msg).to_string();
            let e = anyhow!("GET {url}: {msg}");
            Err(if t.kind() == ureq::ErrorKind::Io { Fault::Retry(e) } else { Fault::Fatal(e) })
        }
    }
}

/// The first byte the response carries and the file's total size, when known. A partial
/// answer for another range empties the part file and is retried.
fn body_range(
    response: &ureq::Response,
    url: &str,
    offset: u64,
    part: &Path,
) -> Result<(u64, Option<u64>), Fault> {
    let length = response.header("Content-Length").and_then(|v| v.trim().parse::<u64>().ok());
    if response.status() != 206 {
        return Ok((0, length));
    }
    match content_range(response.header("Content-Range")) {
        Some((s, total)) if s == offset => Ok((offset, total.or(length.map(|l| l + offset)))),
        _ => {
            truncate(part).map_err(Fault::Fatal)?;
            Err(Fault::Retry(anyhow!(
                "GET {url}: the server answered bytes={offset}- with a different range; \
                 starting again from 0"
            )))
        }
    }
}

/// Streams the response body into the part file from byte `start` on, hashing it and showing
/// progress against `total`; returns the part's length. A broken transfer keeps what arrived
/// (flushed) and is retried.
fn stream_to_part(
    response: ureq::Response,
    (url, part): (&str, &Path),
    start: u64,
    total: Option<u64>,
    hasher: &mut Sha256,
    label: &str,
) -> Result<u64, Fault> {
    let mut file = OpenOptions::new()
        .create(true)
        .write(true)
        .truncate(false)
        .open(part)
        .map_err(disk_fault("opening", part))?;
    file.set_len(start).map_err(disk_fault("truncating", part))?;
    file.seek(SeekFrom::Start(start)).map_err(disk_fault("seeking in", part))?;
    let mut writer = std::io::BufWriter::with_capacity(1 << 20, file);
    let pb = stdx::progress::bytes(label, total);
    pb.set_position(start);
    let mut reader = response.into_reader();
    let mut buf = vec![0u8; 1 << 16];
    let mut len = start;
    loop {
        let n = match reader.read(&mut buf) {
            Ok(0) => break,
            Ok(n) => n,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => continue,
            Err(e) => {
                pb.finish_and_clear();
                writer.flush().map_err(disk_fault("writing", part))?;
                return Err(Fault::Retry(anyhow!(
                    "GET {url}: the transfer broke off after {len} bytes ({e})"
                )));
            }
        };
        writer.write_all(&buf[..n]).map_err(disk_fault("writing", part))?;
        hasher.update(&buf[..n]);
        len += n as u64;
        pb.inc(n as u64);
    }
    pb.finish_and_clear();
    let file = writer.into_inner().map_err(|e| disk_fault("writing", part)(e.into_error()))?;
    file.sync_all().map_err(disk_fault("syncing", part))?;
    Ok(len)
}

/// Empties the part file (the next attempt starts from byte 0).
fn truncate(part: &Path) -> Result<()> {
    std::fs::write(part, b"").with_context(|| format!("truncating {}", part.display()))
}

/// Parses `bytes START-END/TOTAL` or `bytes */TOTAL` into (START, TOTAL); TOTAL may be `*`.
fn content_range(value: Option<&str>) -> Option<(u64, Option<u64>)> {
    let rest = value?.trim().strip_prefix("bytes")?.trim();
    let (range, total) = rest.split_once('/')?;
    let total = if total.trim() == "*" { None } else { Some(total.trim().parse().ok()?) };
    if range.trim() == "*" {
        return Some((u64::MAX, total));
    }
    let (start, _end) = range.split_once('-')?;
    Some((start.trim().parse().ok()?, total))
}

#[cfg(test)]
mod tests {
    use super::content_range;

    #[test]
    fn parses_content_range() {
        assert_eq!(content_range(Some("bytes 10-19/20")), Some((10, Some(20))));
        assert_eq!(content_range(Some("bytes 0-9/*")), Some((0, None)));
        assert_eq!(content_range(Some("bytes */20")), Some((u64::MAX, Some(20))));
        assert_eq!(content_range(Some("items 1-2/3")), None);
        assert_eq!(content_range(None), None);
    }
}
