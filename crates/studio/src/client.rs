//! A client of the studio's server for tests and benchmarks (feature `client`, docs/studio.md,
//! "Protocol"): one tab's WebSocket speaking the page's messages, and raw HTTP requests with a
//! chosen Host header. The studio itself never builds it.

use crate::Running;
use base64::Engine as _;
use base64::engine::general_purpose::STANDARD as BASE64;
use futures_util::{SinkExt, StreamExt};
use serde_json::{Value, json};
use std::io::{Read, Write};
use std::time::Duration;
use tokio_tungstenite::tungstenite::Message;

/// A message from the server.
#[derive(Debug)]
pub enum Msg {
    /// A JSON message.
    Json(Value),
    /// An image: header and PNG.
    Image(Value, Vec<u8>),
}

impl Msg {
    /// The message's `type` ("image" for pictures).
    pub fn kind(&self) -> &str {
        match self {
            Msg::Json(v) => v["type"].as_str().unwrap_or(""),
            Msg::Image(..) => "image",
        }
    }
}

/// The socket's type.
pub type Ws = tokio_tungstenite::WebSocketStream<tokio_tungstenite::MaybeTlsStream<tokio::net::TcpStream>>;

/// One tab's socket.
pub struct Client {
    ws: Ws,
    next_id: u64,
}

impl Client {
    /// Connects to `running`'s socket with its token.
    pub async fn connect(running: &Running) -> Self {
        let url = format!("ws://{}/ws?token={}", running.addr(), running.token());
        let (ws, _) = tokio_tungstenite::connect_async(url).await.expect("the socket opens");
        Self { ws, next_id: 1 }
    }

    /// Connects to the socket of the studio whose page is at `url`, as `mcctrace studio`
    /// prints it (`http://HOST/?token=…`).
    pub async fn connect_url(url: &str) -> Self {
        let url = url.replacen("http://", "ws://", 1).replacen("/?token=", "/ws?token=", 1);
        let (ws, _) = tokio_tungstenite::connect_async(url).await.expect("the socket opens");
        Self { ws, next_id: 1 }
    }

    /// The socket itself.
    pub fn ws_mut(&mut self) -> &mut Ws {
        &mut self.ws
    }

    /// Sends a raw text message.
    pub async fn send_text(&mut self, text: String) {
        self.ws.send(Message::Text(text.into())).await.expect("send");
    }

    /// Sends `message` with a fresh id; returns the id.
    pub async fn send(&mut self, mut message: Value) -> u64 {
        let id = self.next_id;
        self.next_id += 1;
        message["id"] = json!(id);
        self.send_text(message.to_string()).await;
        id
    }

    /// The next message (panics after 60 s of silence or if the socket closes).
    pub async fn recv(&mut self) -> Msg {
        self.try_recv(Duration::from_secs(60)).await.expect("a message from the studio")
    }

    /// The next message, `None` if the socket closed or nothing came within `wait`.
    pub async fn try_recv(&mut self, wait: Duration) -> Option<Msg> {
        loop {
            let next = tokio::time::timeout(wait, self.ws.next()).await.ok()??.ok()?;
            match next {
                Message::Text(text) => {
                    let value: Value = serde_json::from_str(text.as_str()).expect("JSON");
                    if value["type"] == "image" {
                        let png = match tokio::time::timeout(wait, self.ws.next()).await.ok()??.ok()? {
                            Message::Binary(b) => b.to_vec(),
                            other => panic!("an image header must be followed by its PNG, not {other:?}"),
                        };
                        return Some(Msg::Image(value, png));
                    }
                    return Some(Msg::Json(value));
                }
                Message::Close(_) => return None,
                _ => continue,
            }
        }
    }

    /// Messages until one satisfies `want`, which it returns.
    pub async fn until(&mut self, want: impl Fn(&Msg) -> bool) -> Msg {
        loop {
            let m = self.recv().await;
            if want(&m) {
                return m;
            }
        }
    }

    /// Sends `message` and returns the reply that echoes its id.
    pub async fn request(&mut self, message: Value) -> Value {
        let id = self.send(message).await;
        match self.until(|m| matches!(m, Msg::Json(v) if v["id"] == json!(id))).await {
            Msg::Json(v) => v,
            Msg::Image(..) => unreachable!(),
        }
    }

    /// `hello`: the state.
    pub async fn hello(&mut self) -> Value {
        self.request(json!({"type": "hello"})).await
    }

    /// Paints `bytes` at `rect` on the labels.
    pub async fn paint(&mut self, rect: [u32; 4], bytes: &[u8]) -> Value {
        self.paint_layer("labels", rect, bytes).await
    }

    /// Paints `bytes` at `rect` on `layer` ("labels" or "regions").
    pub async fn paint_layer(&mut self, layer: &str, rect: [u32; 4], bytes: &[u8]) -> Value {
        self.request(json!({"type": "paint", "layer": layer, "rect": rect, "data": BASE64.encode(bytes)}))
            .await
    }

    /// The next preview of state `seq` with `spp` samples (older ones skipped).
    pub async fn preview(&mut self, seq: u64, spp: u32) -> (Value, Vec<u8>) {
        match self
            .until(|m| matches!(m, Msg::Image(h, _) if h["kind"] == "preview" && h["seq"] == json!(seq) && h["spp"] == json!(spp)))
            .await
        {
            Msg::Image(h, png) => (h, png),
            Msg::Json(_) => unreachable!(),
        }
    }
}

/// Decodes a base64 map.
pub fn decode(data: &Value) -> Vec<u8> {
    BASE64.decode(data.as_str().expect("a base64 string")).expect("base64")
}

/// A raw HTTP GET of `target` with `host` as the Host header; returns the status code.
pub fn http_get(running: &Running, target: &str, host: &str) -> u16 {
    let mut stream = std::net::TcpStream::connect(running.addr()).expect("connect");
    stream.set_read_timeout(Some(Duration::from_secs(30))).unwrap();
    write!(stream, "GET {target} HTTP/1.1\r\nHost: {host}\r\nConnection: close\r\n\r\n").unwrap();
    let mut response = String::new();
    let _ = stream.read_to_string(&mut response);
    response.split(' ').nth(1).and_then(|s| s.parse().ok()).unwrap_or(0)
}
