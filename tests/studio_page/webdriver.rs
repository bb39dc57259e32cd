//! The W3C WebDriver commands the studio page's test sends to chromedriver, as JSON over HTTP/1.1
//! on loopback: a session, navigation, page scripts, elements by CSS selector, pointer actions
//! and screenshots. (A WebDriver crate would bring its own URL, cookie and Unicode stacks into
//! the test build for these ten requests.)

use base64::Engine;
use base64::engine::general_purpose::STANDARD as BASE64;
use bytes::Bytes;
use http_body_util::{BodyExt, Full};
use hyper::{Method, Request};
use hyper_util::client::legacy::Client;
use hyper_util::client::legacy::connect::HttpConnector;
use hyper_util::rt::TokioExecutor;
use serde_json::{Value, json};

/// The key under which WebDriver names an element (W3C WebDriver, "Elements").
const ELEMENT_KEY: &str = "element-6066-11e4-a52e-4f735466cecf";

/// One WebDriver session on a driver at a loopback URL.
#[derive(Clone)]
pub struct Session {
    http: Client<HttpConnector, Full<Bytes>>,
    /// `http://127.0.0.1:PORT/session/ID`.
    url: String,
}

/// An element of the page, as the session names it.
pub struct Element(String);

impl Element {
    /// The element as a script argument.
    pub fn to_json(&self) -> Value {
        json!({ ELEMENT_KEY: self.0 })
    }
}

/// Sends `body` (or nothing) to `url` and returns the reply's `value`, or the driver's error.
async fn call(
    http: &Client<HttpConnector, Full<Bytes>>,
    method: Method,
    url: &str,
    body: Option<Value>,
) -> Result<Value, String> {
    let bytes = body.map_or_else(Bytes::new, |b| Bytes::from(b.to_string()));
    let request = Request::builder()
        .method(method.clone())
        .uri(url)
        .header("content-type", "application/json; charset=utf-8")
        .body(Full::new(bytes))
        .map_err(|e| e.to_string())?;
    let reply = http.request(request).await.map_err(|e| format!("{method} {url}: {e}"))?;
    let status = reply.status();
    let body = reply.into_body().collect().await.map_err(|e| format!("{method} {url}: {e}"))?.to_bytes();
    let json: Value = serde_json::from_slice(&body).map_err(|e| {
        format!("{method} {url}: {status}, not JSON ({e}): {}", String::from_utf8_lossy(&body))
    })?;
    let value = json.get("value").cloned().unwrap_or(Value::Null);
    if status.is_success() {
        Ok(value)
    } else {
        Err(format!("{method} {url}: {status}: {} ({})", value["error"], value["message"]))
    }
}

impl Session {
    /// Opens a session with `capabilities` on the driver at `driver` (`http://127.0.0.1:PORT`).
    pub async fn new(driver: &str, capabilities: Value) -> Result<Self, String> {
        let http = Client::builder(TokioExecutor::new()).build_http();
        let body = json!({ "capabilities": { "alwaysMatch": capabilities } });
        let value = call(&http, Method::POST, &format!("{driver}/session"), Some(body)).await?;
        let id = value["sessionId"].as_str().ok_or_else(|| format!("no sessionId in {value}"))?;
        Ok(Self { http, url: format!("{driver}/session/{id}") })
    }

    async fn post(&self, path: &str, body: Value) -> Result<Value, String> {
        call(&self.http, Method::POST, &format!("{}{path}", self.url), Some(body)).await
    }

    /// Opens `url` in the session's window.
    pub async fn goto(&self, url: &str) -> Result<(), String> {
        self.post("/url", json!({ "url": url })).await.map(drop)
    }

    /// Runs `script` (a function body; `arguments` holds `args`) and returns what it returns.
    pub async fn execute(&self, script: &str, args: Vec<Value>) -> Result<Value, String> {
        self.post("/execute/sync", json!({ "script": script, "args": args })).await
    }

    /// The first element `css` selects.
    pub async fn find(&self, css: &str) -> Result<Element, String> {
        let value = self.post("/element", json!({ "using": "css selector", "value": css })).await?;
        let id = value[ELEMENT_KEY].as_str().ok_or_else(|| format!("no element in {value}"))?;
        Ok(Element(id.to_string()))
    }

    /// Clicks `element`.
    pub async fn click(&self, element: &Element) -> Result<(), String> {
        self.post(&format!("/element/{}/click", element.0), json!({})).await.map(drop)
    }

    /// Empties the input `element`.
    pub async fn clear(&self, element: &Element) -> Result<(), String> {
        self.post(&format!("/element/{}/clear", element.0), json!({})).await.map(drop)
    }

    /// Types `text` into `element`.
    pub async fn send_keys(&self, element: &Element, text: &str) -> Result<(), String> {
        self.post(&format!("/element/{}/value", element.0), json!({ "text": text })).await.map(drop)
    }

    /// Performs one mouse's pointer `actions` (W3C action items: pointerMove, pointerDown, …),
    /// then releases every input, as a user lets go.
    pub async fn mouse(&self, actions: Vec<Value>) -> Result<(), String> {
        let source = json!({ "type": "pointer", "id": "mouse", "parameters": { "pointerType": "mouse" }, "actions": actions });
        self.post("/actions", json!({ "actions": [source] })).await?;
        call(&self.http, Method::DELETE, &format!("{}/actions", self.url), None).await.map(drop)
    }

    /// A PNG screenshot of the window.
    pub async fn screenshot(&self) -> Result<Vec<u8>, String> {
        let value = call(&self.http, Method::GET, &format!("{}/screenshot", self.url), None).await?;
        let text = value.as_str().ok_or_else(|| format!("no screenshot in {value}"))?;
        BASE64.decode(text).map_err(|e| format!("the screenshot's base64: {e}"))
    }

    /// Ends the session (the browser quits).
    pub async fn close(&self) -> Result<(), String> {
        call(&self.http, Method::DELETE, &self.url, None).await.map(drop)
    }
}
