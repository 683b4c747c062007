//! Connections. Each carries one request, whose head is read, parsed and held to the
//! studio's limits here before hyper sees it, so that an over-long URL (414), an over-long
//! or over-full head (431) and a malformed one (400) get a JSON answer like every other
//! refusal, instead of hyper's bare status line. One request a connection keeps that
//! simple (no framing of bodies to follow between requests); on loopback a new connection
//! costs tens of microseconds.

use std::future::Future;
use std::io;
use std::pin::{Pin, pin};
use std::task::{Context, Poll};
use std::time::Duration;

use axum::Router;
use axum::http::StatusCode;
use hyper_util::rt::TokioIo;
use hyper_util::service::TowerToHyperService;
use tokio::io::{AsyncRead, AsyncReadExt, AsyncWrite, AsyncWriteExt, ReadBuf};
use tokio::net::{TcpListener, TcpStream};

use crate::error::ApiError;

/// The longest request target (path and query), bytes.
pub const MAX_URI: usize = 8 << 10;
/// The longest request head (request line and headers), bytes.
pub const MAX_HEAD: usize = 64 << 10;
/// The most header lines a request may have.
pub const MAX_HEADERS: usize = 96;
/// How long a client may take to send its head.
const HEAD_TIMEOUT: Duration = Duration::from_secs(30);

/// Serves `app` on `listener` until `shutdown` completes.
pub async fn serve(
    listener: TcpListener,
    app: Router,
    shutdown: impl Future<Output = ()>,
) -> io::Result<()> {
    let mut shutdown = pin!(shutdown);
    loop {
        let stream = tokio::select! {
            accepted = listener.accept() => match accepted {
                Ok((stream, _)) => stream,
                // Out of file descriptors and the like: wait, then accept again.
                Err(_) => {
                    tokio::time::sleep(Duration::from_millis(50)).await;
                    continue;
                }
            },
            () = &mut shutdown => return Ok(()),
        };
        let app = app.clone();
        tokio::spawn(async move {
            let _ = connection(stream, app).await;
        });
    }
}

/// One connection: its request's head checked, then the request served by hyper.
async fn connection(mut stream: TcpStream, app: Router) -> io::Result<()> {
    let _ = stream.set_nodelay(true);
    let head = match tokio::time::timeout(HEAD_TIMEOUT, read_head(&mut stream)).await {
        Ok(head) => head?,
        Err(_) => Err(ApiError::new(
            StatusCode::REQUEST_TIMEOUT,
            "",
            format!(
                "the request head did not arrive within {} s",
                HEAD_TIMEOUT.as_secs()
            ),
        )),
    };
    let buffered = match head {
        Ok(Some(bytes)) => bytes,
        Ok(None) => return Ok(()), // closed before a request
        Err(refusal) => return refuse(stream, &refusal).await,
    };
    let io = TokioIo::new(Prefixed {
        buffered,
        at: 0,
        inner: stream,
    });
    let mut http = hyper::server::conn::http1::Builder::new();
    http.keep_alive(false).max_headers(MAX_HEADERS + 1);
    http.serve_connection(io, TowerToHyperService::new(app))
        .await
        .map_err(io::Error::other)
}

/// Reads a request head (and whatever came after it), or the refusal to answer.
async fn read_head(stream: &mut TcpStream) -> io::Result<Result<Option<Vec<u8>>, ApiError>> {
    let mut buffer = Vec::with_capacity(4096);
    let mut chunk = [0u8; 4096];
    loop {
        let n = stream.read(&mut chunk).await?;
        if n == 0 {
            return Ok(if buffer.is_empty() {
                Ok(None)
            } else {
                Err(ApiError::bad("", "the request head ended early"))
            });
        }
        let searched = buffer.len().saturating_sub(3);
        buffer.extend_from_slice(&chunk[..n]);
        let end = buffer[searched..]
            .windows(4)
            .position(|w| w == b"\r\n\r\n")
            .map(|i| searched + i + 4);
        if let Err(refusal) = check_target(&buffer) {
            return Ok(Err(refusal));
        }
        match end {
            Some(end) if end <= MAX_HEAD => {
                return Ok(check_head(&buffer[..end]).map(|()| Some(buffer)));
            }
            _ if buffer.len() > MAX_HEAD => return Ok(Err(head_too_large())),
            _ => {}
        }
    }
}

/// Refuses a request target longer than [`MAX_URI`], as soon as its length shows.
fn check_target(buffer: &[u8]) -> Result<(), ApiError> {
    let line_end = buffer
        .windows(2)
        .position(|w| w == b"\r\n")
        .unwrap_or(buffer.len());
    let line = &buffer[..line_end];
    let start = line.iter().position(|&b| b == b' ').map_or(0, |i| i + 1);
    let target_end = line[start..]
        .iter()
        .position(|&b| b == b' ')
        .map_or(line.len(), |i| start + i);
    if target_end - start > MAX_URI {
        return Err(ApiError::new(
            StatusCode::URI_TOO_LONG,
            "",
            format!("the URL is longer than {MAX_URI} bytes"),
        ));
    }
    Ok(())
}

fn head_too_large() -> ApiError {
    ApiError::new(
        StatusCode::REQUEST_HEADER_FIELDS_TOO_LARGE,
        "",
        format!("the request's headers are larger than {MAX_HEAD} bytes"),
    )
}

/// Parses a whole head as hyper would, so that a malformed one is answered here in JSON.
fn check_head(head: &[u8]) -> Result<(), ApiError> {
    let mut headers = [httparse::EMPTY_HEADER; MAX_HEADERS];
    let mut request = httparse::Request::new(&mut headers);
    match request.parse(head) {
        Ok(httparse::Status::Complete(_)) => {}
        Ok(httparse::Status::Partial) => {
            return Err(ApiError::bad("", "the request head ended early"));
        }
        Err(httparse::Error::TooManyHeaders) => {
            return Err(ApiError::new(
                StatusCode::REQUEST_HEADER_FIELDS_TOO_LARGE,
                "",
                format!("the request has more than {MAX_HEADERS} headers"),
            ));
        }
        Err(e) => return Err(ApiError::bad("", format!("a malformed request head: {e}"))),
    }
    let lengths: Vec<&[u8]> = request
        .headers
        .iter()
        .filter(|h| h.name.eq_ignore_ascii_case("content-length"))
        .map(|h| h.value)
        .collect();
    let valid = |v: &[u8]| !v.is_empty() && v.len() <= 19 && v.iter().all(u8::is_ascii_digit);
    if lengths.len() > 1 || lengths.iter().any(|v| !valid(v)) {
        return Err(ApiError::bad(
            "",
            "the request needs one Content-Length of digits",
        ));
    }
    Ok(())
}

/// Answers a refusal before hyper and closes, reading (a little of) what the client still
/// sends, so that it sees the answer rather than a reset connection.
async fn refuse(mut stream: TcpStream, refusal: &ApiError) -> io::Result<()> {
    let body = refusal.body();
    let head = format!(
        "HTTP/1.1 {} {}\r\ncontent-type: application/json\r\ncontent-length: {}\r\nconnection: close\r\n\r\n",
        refusal.status.as_u16(),
        refusal.status.canonical_reason().unwrap_or(""),
        body.len()
    );
    stream.write_all(head.as_bytes()).await?;
    stream.write_all(body.as_bytes()).await?;
    stream.flush().await?;
    stream.shutdown().await?;
    let mut sink = [0u8; 4096];
    let drain = async {
        let mut left = 1usize << 20;
        while left > 0 {
            match stream.read(&mut sink).await {
                Ok(0) | Err(_) => break,
                Ok(n) => left = left.saturating_sub(n),
            }
        }
    };
    let _ = tokio::time::timeout(Duration::from_secs(1), drain).await;
    Ok(())
}

/// A stream that first gives back the bytes already read from it.
struct Prefixed {
    buffered: Vec<u8>,
    at: usize,
    inner: TcpStream,
}

impl AsyncRead for Prefixed {
    fn poll_read(
        mut self: Pin<&mut Self>,
        cx: &mut Context<'_>,
        buf: &mut ReadBuf<'_>,
    ) -> Poll<io::Result<()>> {
        let this = &mut *self;
        if this.at < this.buffered.len() {
            let n = (this.buffered.len() - this.at).min(buf.remaining());
            buf.put_slice(&this.buffered[this.at..this.at + n]);
            this.at += n;
            if this.at == this.buffered.len() {
                this.buffered = Vec::new();
                this.at = 0;
            }
            return Poll::Ready(Ok(()));
        }
        Pin::new(&mut this.inner).poll_read(cx, buf)
    }
}

impl AsyncWrite for Prefixed {
    fn poll_write(
        mut self: Pin<&mut Self>,
        cx: &mut Context<'_>,
        data: &[u8],
    ) -> Poll<io::Result<usize>> {
        Pin::new(&mut self.inner).poll_write(cx, data)
    }

    fn poll_flush(mut self: Pin<&mut Self>, cx: &mut Context<'_>) -> Poll<io::Result<()>> {
        Pin::new(&mut self.inner).poll_flush(cx)
    }

    fn poll_shutdown(mut self: Pin<&mut Self>, cx: &mut Context<'_>) -> Poll<io::Result<()>> {
        Pin::new(&mut self.inner).poll_shutdown(cx)
    }

    fn poll_write_vectored(
        mut self: Pin<&mut Self>,
        cx: &mut Context<'_>,
        bufs: &[io::IoSlice<'_>],
    ) -> Poll<io::Result<usize>> {
        Pin::new(&mut self.inner).poll_write_vectored(cx, bufs)
    }

    fn is_write_vectored(&self) -> bool {
        self.inner.is_write_vectored()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn long_targets_are_seen_before_the_line_ends() {
        let mut line = b"GET /".to_vec();
        line.extend(std::iter::repeat_n(b'a', MAX_URI));
        assert_eq!(check_target(&line).map_err(|e| e.status.as_u16()), Err(414));
        assert!(check_target(b"GET /api/models HTTP/1.1\r\nHost: x\r\n").is_ok());
        assert!(check_target(b"GE").is_ok());
    }

    #[test]
    fn heads_are_parsed_as_hyper_would() {
        let ok = b"POST /api/sessions HTTP/1.1\r\nHost: a\r\nContent-Length: 2\r\n\r\n";
        assert!(check_head(ok).is_ok());
        for bad in [
            &b"POST /api HTTP/1.1\r\nHost: a\r\nContent-Length: 2\r\nContent-Length: 3\r\n\r\n"[..],
            b"POST /api HTTP/1.1\r\nContent-Length: -1\r\n\r\n",
            b"POST /api HTTP/1.1\r\nContent-Length: 99999999999999999999\r\n\r\n",
            b"GET /api HTTP/9\r\n\r\n",
            b"G\x01T /api HTTP/1.1\r\n\r\n",
            b"GET /api HTTP/1.1\r\nBad Header: x\r\n\r\n",
        ] {
            assert_eq!(
                check_head(bad).map_err(|e| e.status.as_u16()),
                Err(400),
                "{}",
                String::from_utf8_lossy(bad)
            );
        }
        let mut many = b"GET / HTTP/1.1\r\n".to_vec();
        for i in 0..=MAX_HEADERS {
            many.extend(format!("X-{i}: 1\r\n").as_bytes());
        }
        many.extend(b"\r\n");
        assert_eq!(check_head(&many).map_err(|e| e.status.as_u16()), Err(431));
    }
}
