//! Headless Chromium driven through chromedriver (WebDriver) for the studio page's test: the
//! flags Chromium needs as root on a closed network, real pointer strokes, page scripts, and
//! waiting for the page's state.

use super::webdriver::Session;
use base64::Engine;
use base64::engine::general_purpose::STANDARD as BASE64;
use serde_json::{Value, json};
use std::net::TcpListener;
use std::os::unix::process::CommandExt;
use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

/// A free loopback port (bound, read and released; a race with another process is unlikely).
pub fn free_port() -> u16 {
    TcpListener::bind("127.0.0.1:0").expect("bind a loopback port").local_addr().unwrap().port()
}

/// A chromedriver process and one headless Chromium session through it; both end on drop.
pub struct Browser {
    /// The WebDriver session.
    pub client: Session,
    driver: Child,
}

impl Browser {
    /// Starts chromedriver on a free port and a headless Chromium with a fresh profile in
    /// `profile`, its window `width`×`height`.
    pub async fn start(chromium: &Path, chromedriver: &Path, profile: &Path, size: (u32, u32)) -> Self {
        let port = free_port();
        let driver = Command::new(chromedriver)
            .arg(format!("--port={port}"))
            .process_group(0)
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .expect("start chromedriver");
        // Without the networking flags Chromium keeps calling home on a closed network and
        // hangs; as root it needs --no-sandbox.
        let args = [
            "--headless".to_string(),
            "--no-sandbox".into(),
            "--disable-gpu".into(),
            "--disable-quic".into(),
            "--no-first-run".into(),
            "--disable-background-networking".into(),
            "--disable-component-update".into(),
            "--disable-sync".into(),
            "--disable-dev-shm-usage".into(),
            format!("--user-data-dir={}", profile.display()),
            format!("--window-size={},{}", size.0, size.1),
        ];
        let mut caps = serde_json::Map::new();
        caps.insert("goog:chromeOptions".into(), json!({ "binary": chromium, "args": args }));
        let url = format!("http://127.0.0.1:{port}");
        let deadline = Instant::now() + Duration::from_secs(60);
        let client = loop {
            match Session::new(&url, Value::Object(caps.clone())).await {
                Ok(client) => break client,
                Err(e) if Instant::now() > deadline => panic!("no WebDriver session from chromedriver: {e}"),
                Err(_) => tokio::time::sleep(Duration::from_millis(200)).await,
            }
        };
        Self { client, driver }
    }

    /// Runs `script` (a function body; `arguments` holds `args`) in the page.
    pub async fn js(&self, script: &str, args: Vec<Value>) -> Value {
        self.client
            .execute(script, args)
            .await
            .unwrap_or_else(|e| panic!("page script failed: {e}\n{script}"))
    }

    /// The bytes of the typed array (or null) `script` returns, carried as base64: a picture
    /// as a JSON array of numbers would hold the page's main thread for hundreds of ms at
    /// 480×270, a long task of the test's own making in the page's record.
    pub async fn bytes(&self, script: &str) -> Option<Vec<u8>> {
        let wrapped = format!(
            "const a = (() => {{ {script} }})(); if (a == null) return null;
             const u = new Uint8Array(a.buffer, a.byteOffset, a.byteLength);
             let s = ''; for (let i = 0; i < u.length; i += 0x8000) s += String.fromCharCode.apply(null, u.subarray(i, i + 0x8000));
             return btoa(s);"
        );
        let text = self.js(&wrapped, vec![]).await;
        let text = text.as_str()?;
        Some(BASE64.decode(text).unwrap_or_else(|e| panic!("the page's base64: {e}\n{script}")))
    }

    /// Polls `script` until it returns something other than null or false, for up to `limit`.
    pub async fn wait_for(&self, what: &str, script: &str, limit: Duration) -> Value {
        self.wait_for_with(what, script, vec![], limit).await
    }

    /// [`Browser::wait_for`] with `args` as the script's `arguments`.
    pub async fn wait_for_with(&self, what: &str, script: &str, args: Vec<Value>, limit: Duration) -> Value {
        let deadline = Instant::now() + limit;
        loop {
            let v = self.js(script, args.clone()).await;
            if !(v.is_null() || v == Value::Bool(false)) {
                return v;
            }
            if Instant::now() > deadline {
                let status = self.js("return [document.getElementById('status').innerText, window.studio && window.studio.errors]", vec![]).await;
                panic!("timed out after {limit:?} waiting for {what}; page status and errors: {status}");
            }
            tokio::time::sleep(Duration::from_millis(50)).await;
        }
    }

    /// Clicks the element `css` selects.
    pub async fn click(&self, css: &str) {
        let element = self.client.find(css).await.unwrap_or_else(|e| panic!("no `{css}`: {e}"));
        self.client.click(&element).await.unwrap_or_else(|e| panic!("click `{css}`: {e}"));
    }

    /// Types `text` into the input `css` selects, replacing its value, and fires its change event.
    pub async fn type_into(&self, css: &str, text: &str) {
        let element = self.client.find(css).await.unwrap_or_else(|e| panic!("no `{css}`: {e}"));
        self.client.clear(&element).await.unwrap_or_else(|e| panic!("clear `{css}`: {e}"));
        self.client.send_keys(&element, text).await.unwrap_or_else(|e| panic!("type into `{css}`: {e}"));
        self.js("arguments[0].dispatchEvent(new Event('change', {bubbles: true}))", vec![element.to_json()])
            .await;
    }

    /// Drags the mouse with the left button through `points` (viewport pixels), as a user would:
    /// press at the first, move through the rest, release at the last.
    pub async fn drag(&self, points: &[(f64, f64)]) {
        let move_to = |(x, y): (f64, f64), ms: u64| json!({ "type": "pointerMove", "duration": ms, "origin": "viewport", "x": x.round() as i64, "y": y.round() as i64 });
        let mut actions = vec![move_to(points[0], 0), json!({ "type": "pointerDown", "button": 0 })];
        actions.extend(points[1..].iter().map(|&p| move_to(p, 30)));
        actions.push(json!({ "type": "pointerUp", "button": 0 }));
        self.client.mouse(actions).await.unwrap_or_else(|e| panic!("the pointer actions: {e}"));
    }

    /// A PNG screenshot of the page.
    pub async fn screenshot(&self) -> Vec<u8> {
        self.client.screenshot().await.unwrap_or_else(|e| panic!("take a screenshot: {e}"))
    }
}

impl Browser {
    /// Ends the WebDriver session (Chromium quits) before chromedriver is stopped.
    pub async fn quit(self) {
        let _ = self.client.close().await;
    }
}

impl Drop for Browser {
    fn drop(&mut self) {
        // Killing chromedriver alone leaves Chromium running (a failed test never reaches
        // `quit`), so the whole process group it started in ends, Chromium's processes with it.
        // SAFETY: kill takes plain integers; the group is the one this test started.
        unsafe { libc::kill(-(self.driver.id() as i32), libc::SIGKILL) };
        let _ = self.driver.wait();
    }
}
