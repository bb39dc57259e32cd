//! The checks every request passes first (docs/studio.md, "Safe by default"): the URL's token
//! (compared in constant time) and a Host header naming the loopback address and port (or the
//! `--listen` address), which defeats DNS rebinding; an `Origin` header, when there is one (a
//! browser sends it on every WebSocket handshake), must be `http://` and one of those same
//! hosts, so no other site's page can open the studio's socket even holding the token.

use super::AppState;
use axum::extract::{Request, State};
use axum::http::{StatusCode, header};
use axum::middleware::Next;
use axum::response::{IntoResponse, Response};
use std::net::{IpAddr, SocketAddr};

/// The token and the Host names a request must carry.
pub struct Guard {
    token: String,
    hosts: Vec<String>,
}

impl Guard {
    /// The guard of a server on `addr` started with `--listen listen` and `token`.
    pub fn new(token: String, addr: SocketAddr, listen: IpAddr) -> Self {
        let port = addr.port();
        let mut hosts =
            vec![format!("127.0.0.1:{port}"), format!("localhost:{port}"), format!("[::1]:{port}")];
        if !listen.is_loopback() && !listen.is_unspecified() {
            hosts.push(SocketAddr::new(listen, port).to_string());
        }
        Self { token, hosts }
    }

    /// Why `host`, `origin` and `query` are refused, if they are.
    pub fn refusal(
        &self,
        host: Option<&str>,
        origin: Option<&str>,
        query: Option<&str>,
    ) -> Option<&'static str> {
        let allowed = |h: &str| self.hosts.iter().any(|allowed| allowed.eq_ignore_ascii_case(h));
        if !host.is_some_and(allowed) {
            return Some("the Host header is not this studio's loopback address");
        }
        if let Some(origin) = origin
            && !origin.strip_prefix("http://").is_some_and(allowed)
        {
            return Some("the Origin header is not this studio's page: open the URL the studio printed");
        }
        let token = query.into_iter().flat_map(|q| q.split('&')).find_map(|kv| kv.strip_prefix("token="));
        match token {
            Some(t) if constant_time_eq(t.as_bytes(), self.token.as_bytes()) => None,
            _ => Some("missing or wrong token: open the URL the studio printed"),
        }
    }
}

/// Equality that takes as long whatever the first difference.
fn constant_time_eq(a: &[u8], b: &[u8]) -> bool {
    a.len() == b.len() && a.iter().zip(b).fold(0u8, |acc, (x, y)| acc | (x ^ y)) == 0
}

/// A random token: 128 bits from the system's generator, in hex.
pub fn random_token() -> String {
    let mut bytes = [0u8; 16];
    getrandom::fill(&mut bytes).expect("the system's random generator works");
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}

/// The middleware: 403 for a refused request.
pub async fn check(State(state): State<AppState>, request: Request, next: Next) -> Response {
    let refusal = {
        let text = |name| request.headers().get(name).map(|h| h.to_str().unwrap_or("(not text)"));
        state.guard.refusal(text(header::HOST), text(header::ORIGIN), request.uri().query())
    };
    match refusal {
        None => next.run(request).await,
        Some(why) => (StatusCode::FORBIDDEN, why).into_response(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn refuses_other_hosts_and_wrong_tokens() {
        let addr: SocketAddr = "127.0.0.1:4321".parse().unwrap();
        let g = Guard::new("abc".into(), addr, "127.0.0.1".parse().unwrap());
        let local = Some("127.0.0.1:4321");
        assert_eq!(g.refusal(Some("localhost:4321"), None, Some("token=abc")), None);
        assert_eq!(g.refusal(Some("[::1]:4321"), None, Some("x=1&token=abc")), None);
        assert!(g.refusal(Some("evil.example:4321"), None, Some("token=abc")).is_some());
        assert!(g.refusal(Some("127.0.0.1:80"), None, Some("token=abc")).is_some());
        assert!(g.refusal(None, None, Some("token=abc")).is_some());
        assert!(g.refusal(local, None, Some("token=abd")).is_some());
        assert!(g.refusal(local, None, None).is_some());
        assert_eq!(g.refusal(local, Some("http://localhost:4321"), Some("token=abc")), None);
        for origin in
            ["http://evil.example", "http://127.0.0.1:80", "null", "https://127.0.0.1:4321", "(not text)"]
        {
            assert!(g.refusal(local, Some(origin), Some("token=abc")).is_some(), "{origin}");
        }
        assert_eq!(random_token().len(), 32);
        assert_ne!(random_token(), random_token());
    }
}
