//! The studio's server over real HTTP and WebSocket (docs/studio.md): a client that speaks the
//! page's protocol, and the tests of editing, saving, the final render and the refusals of
//! "Safe by default".

mod api;
mod project;
mod safety;

use ::studio::{Config, EngineSettings, Running};
use base64::Engine as _;
use base64::engine::general_purpose::STANDARD as BASE64;
use futures_util::{SinkExt, StreamExt};
use serde_json::{Value, json};
use std::io::{Read, Write};
use std::path::{Path, PathBuf};
use std::time::Duration;
use tokio_tungstenite::tungstenite::Message;

/// The Cornell box glTF (one camera; tests duplicate it).
pub fn scene() -> PathBuf {
    crate::common::cornell_dir().join("cornell.gltf")
}

/// A fresh scratch folder under the target directory.
pub fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("mcctrace-studio-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Small settings so tests run in seconds.
pub const RES: [u32; 2] = [48, 32];
pub const SETTINGS: EngineSettings = EngineSettings { preview_spp: 4, view_spp: 2, coarse_divisor: 4 };

/// A studio on the Cornell box at [`RES`], saving to `dir`.
pub fn start(dir: &Path) -> Running {
    let config = Config { res: RES, engine: SETTINGS, ..Config::new(Some(scene()), dir.to_path_buf()) };
    ::studio::serve(config).expect("the studio starts")
}

/// A message from the server.
#[derive(Debug)]
pub enum Msg {
    /// A JSON message.
    Json(Value),
    /// An image: header and PNG.
    Image(Value, Vec<u8>),
}

impl Msg {
    pub fn kind(&self) -> &str {
        match self {
            Msg::Json(v) => v["type"].as_str().unwrap_or(""),
            Msg::Image(..) => "image",
        }
    }
}

type Ws = tokio_tungstenite::WebSocketStream<tokio_tungstenite::MaybeTlsStream<tokio::net::TcpStream>>;

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
        self.request(json!({"type": "paint", "layer": "labels", "rect": rect, "data": BASE64.encode(bytes)}))
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

/// Two cameras painted side by side: duplicates camera 1, turns the copy, and paints the left
/// third with camera 1 and the right third with camera 2. Returns the state after the paint.
pub async fn two_strokes(client: &mut Client) -> Value {
    let state = client.hello().await;
    let first = state["cameras"][0].clone();
    let state = client.request(json!({"type": "camera_duplicate", "index": 1})).await;
    assert_eq!(state["cameras"].as_array().unwrap().len(), 2, "{state}");
    let eye = first["eye"].as_array().unwrap().iter().map(|v| v.as_f64().unwrap()).collect::<Vec<_>>();
    let moved = json!({"type": "camera_edit", "index": 2, "eye": [eye[0] + 0.6, eye[1], eye[2]],
                       "target": first["target"], "up": first["up"], "fov_deg": 35.0});
    let state = client.request(moved).await;
    assert_eq!(state["type"], "state", "{state}");
    let [w, h] = RES;
    let third = w / 3;
    client.paint([0, 0, third, h], &vec![1; (third * h) as usize]).await;
    client.paint([w - third, 0, third, h], &vec![2; (third * h) as usize]).await
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
