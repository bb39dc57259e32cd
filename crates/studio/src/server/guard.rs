//! The checks every request passes first (docs/studio.md, "Safe by default"): the URL's token
//! (compared in constant time) and a Host header naming the loopback address and port (or the
//! `--listen` address), which defeats DNS rebinding.

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

    /// Why `host` and `query` are refused, if they are.
    pub fn refusal(&self, host: Option<&str>, query: Option<&str>) -> Option<&'static str> {
        let host_ok = host.is_some_and(|h| self.hosts.iter().any(|allowed| allowed.eq_ignore_ascii_case(h)));
        if !host_ok {
            return Some("the Host header is not this studio's loopback address");
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
    let host = request.headers().get(header::HOST).and_then(|h| h.to_str().ok());
    match state.guard.refusal(host, request.uri().query()) {
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
        assert_eq!(g.refusal(Some("localhost:4321"), Some("token=abc")), None);
        assert_eq!(g.refusal(Some("[::1]:4321"), Some("x=1&token=abc")), None);
        assert!(g.refusal(Some("evil.example:4321"), Some("token=abc")).is_some());
        assert!(g.refusal(Some("127.0.0.1:80"), Some("token=abc")).is_some());
        assert!(g.refusal(None, Some("token=abc")).is_some());
        assert!(g.refusal(Some("127.0.0.1:4321"), Some("token=abd")).is_some());
        assert!(g.refusal(Some("127.0.0.1:4321"), None).is_some());
        assert_eq!(random_token().len(), 32);
        assert_ne!(random_token(), random_token());
    }
}
