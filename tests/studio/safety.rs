//! "Safe by default" (docs/studio.md): each refused request is refused.

use super::{Client, http_get, scratch, start};
use futures_util::SinkExt;
use serde_json::json;
use std::time::Duration;
use tokio_tungstenite::tungstenite::Message;

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn refuses_what_it_must() {
    let dir = scratch("safety");
    let running = start(&dir);
    assert!(running.addr().ip().is_loopback(), "the default address is loopback");
    let port = running.addr().port();
    let token = running.token().to_owned();
    let host = format!("127.0.0.1:{port}");
    assert_eq!(http_get(&running, &format!("/?token={token}"), &host), 200);
    assert_eq!(http_get(&running, &format!("/?token={token}"), &format!("localhost:{port}")), 200);
    assert_eq!(http_get(&running, "/", &host), 403, "no token");
    assert_eq!(http_get(&running, "/?token=0123", &host), 403, "wrong token");
    assert_eq!(http_get(&running, &format!("/assets/index.html?token={token}x"), &host), 403);
    assert_eq!(
        http_get(&running, &format!("/?token={token}"), &format!("attacker.example:{port}")),
        403,
        "DNS rebinding"
    );
    assert_eq!(http_get(&running, &format!("/?token={token}"), "127.0.0.1:1"), 403, "another port");
    assert_eq!(http_get(&running, &format!("/ws?token={token}"), "evil:1"), 403);
    assert_eq!(http_get(&running, "/ws", &host), 403);
    for path in ["..%2F..%2FCargo.toml", "..%2Fsrc%2Flib.rs", "%2Fetc%2Fpasswd"] {
        let status = http_get(&running, &format!("/assets/{path}?token={token}"), &host);
        assert_eq!(status, 404, "{path} must not reach a file");
    }
    let upgrade = format!("ws://{}/ws?token=nope", running.addr());
    assert!(tokio_tungstenite::connect_async(upgrade).await.is_err(), "a socket without the token");
    // Issue 41, item 15: another site's page holding the token cannot open the socket: the
    // Origin a browser sends must be the studio's own page.
    for (origin, opens) in [
        (format!("http://127.0.0.1:{port}"), true),
        (format!("http://localhost:{port}"), true),
        ("http://attacker.example".to_owned(), false),
        (format!("http://attacker.example:{port}"), false),
        ("null".to_owned(), false),
    ] {
        assert_eq!(socket_with_origin(&running, &origin).await, opens, "Origin {origin}");
    }

    // An oversized message closes the socket and changes nothing.
    let mut client = Client::connect(&running).await;
    let seq = client.hello().await["seq"].clone();
    let huge = "x".repeat(::studio::server::MAX_MESSAGE + 1);
    let _ = client_send_raw(&mut client, huge).await;
    assert!(client.try_recv(Duration::from_secs(20)).await.is_none_or(|m| m.kind() != "state"));
    let mut fresh = Client::connect(&running).await;
    assert_eq!(fresh.hello().await["seq"], seq);
    // A message naming a camera that does not exist is refused.
    let reply = fresh.request(json!({"type": "view", "mode": "labels", "camera": 99})).await;
    assert_eq!(reply["type"], "error");
    drop(running);
    std::fs::remove_dir_all(&dir).unwrap();
}

async fn client_send_raw(client: &mut Client, text: String) -> Result<(), ()> {
    client.ws_mut().send(Message::Text(text.into())).await.map_err(|_| ())
}

/// Whether a WebSocket with the right token and `origin` as its Origin header opens.
async fn socket_with_origin(running: &::studio::Running, origin: &str) -> bool {
    use tokio_tungstenite::tungstenite::client::IntoClientRequest;
    let url = format!("ws://{}/ws?token={}", running.addr(), running.token());
    let mut request = url.into_client_request().unwrap();
    request.headers_mut().insert("origin", origin.parse().unwrap());
    tokio_tungstenite::connect_async(request).await.is_ok()
}
