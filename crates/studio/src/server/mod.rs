//! The studio's HTTP server (docs/studio.md, "Server" and "Safe by default"): the page and its
//! assets, embedded; one WebSocket per tab. Every request needs the URL's token and a loopback
//! Host header (or the `--listen` address), which stops other sites' pages and DNS rebinding.

mod guard;
mod handle;
mod socket;

use crate::config::Config;
use crate::engine::{Shared, start_worker};
use crate::error::{Result, StudioError};
use axum::Router;
use axum::extract::{Path, State, WebSocketUpgrade};
use axum::http::{StatusCode, header};
use axum::response::{IntoResponse, Response};
use axum::routing::get;
use std::net::SocketAddr;
use std::sync::Arc;

/// Largest WebSocket message accepted (a whole 4096 × 4096 map in base64 fits).
pub const MAX_MESSAGE: usize = 24 << 20;

/// The page's files (`crates/studio/assets/`), embedded by `build.rs`: (name, bytes).
const ASSETS: &[(&str, &[u8])] = include!(concat!(env!("OUT_DIR"), "/assets.rs"));

/// The content type of an asset, by its extension.
fn content_type(name: &str) -> &'static str {
    match name.rsplit_once('.').map(|(_, e)| e) {
        Some("html") => "text/html; charset=utf-8",
        Some("js") => "text/javascript; charset=utf-8",
        Some("css") => "text/css; charset=utf-8",
        Some("png") => "image/png",
        Some("svg") => "image/svg+xml",
        _ => "application/octet-stream",
    }
}

/// A running studio.
pub struct Running {
    url: String,
    addr: SocketAddr,
    token: String,
    shared: Arc<Shared>,
    shutdown: Option<tokio::sync::oneshot::Sender<()>>,
    thread: Option<std::thread::JoinHandle<()>>,
    worker: Option<std::thread::JoinHandle<()>>,
}

impl Running {
    /// The page's URL, with its token.
    pub fn url(&self) -> &str {
        &self.url
    }

    /// The address listened on.
    pub fn addr(&self) -> SocketAddr {
        self.addr
    }

    /// The token every request must carry.
    pub fn token(&self) -> &str {
        &self.token
    }

    /// Blocks until the server stops (it runs until the process ends).
    pub fn wait(mut self) {
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }

    /// Keeps unsaved changes in the autosave beside the project (docs/studio.md, "Autosave");
    /// returns its folder, or `None` when nothing was unsaved.
    pub fn autosave(&self) -> Result<Option<std::path::PathBuf>> {
        crate::project::autosave::autosave(&self.shared)
    }

    /// The project folder saves go to.
    pub fn project(&self) -> &std::path::Path {
        &self.shared.project
    }

    /// Stops the server and the engine.
    pub fn stop(mut self) {
        self.halt();
    }

    fn halt(&mut self) {
        if let Some(tx) = self.shutdown.take() {
            let _ = tx.send(());
        }
        self.shared.stop();
        for t in [self.thread.take(), self.worker.take()].into_iter().flatten() {
            let _ = t.join();
        }
    }
}

impl Drop for Running {
    fn drop(&mut self) {
        self.halt();
    }
}

/// What every handler sees.
#[derive(Clone)]
struct AppState {
    shared: Arc<Shared>,
    guard: Arc<guard::Guard>,
}

/// Starts the studio: loads the scene (or opens the project), binds the address and serves on
/// a thread of its own; returns at once with the URL.
pub fn serve(config: Config) -> Result<Running> {
    let shared = Arc::new(crate::project::open_session(&config)?);
    crate::engine::open_denoiser(&shared);
    let listener = std::net::TcpListener::bind((config.listen, config.port)).map_err(|e| {
        StudioError::Server(format!("cannot listen on {}:{}: {e}", config.listen, config.port))
    })?;
    let addr = listener.local_addr().map_err(|e| StudioError::Server(e.to_string()))?;
    listener.set_nonblocking(true).map_err(|e| StudioError::Server(e.to_string()))?;
    let token = config.token.clone().unwrap_or_else(guard::random_token);
    let guard = Arc::new(guard::Guard::new(token.clone(), addr, config.listen));
    let state = AppState { shared: Arc::clone(&shared), guard };
    let app = Router::new()
        .route("/", get(index))
        .route("/assets/{name}", get(asset))
        .route("/ws", get(websocket))
        .layer(axum::middleware::from_fn_with_state(state.clone(), guard::check))
        .with_state(state);
    let runtime = tokio::runtime::Builder::new_multi_thread()
        .worker_threads(2)
        .enable_all()
        .build()
        .map_err(|e| StudioError::Server(format!("cannot start the runtime: {e}")))?;
    let (tx, rx) = tokio::sync::oneshot::channel::<()>();
    let listener = {
        let _enter = runtime.enter();
        tokio::net::TcpListener::from_std(listener).map_err(|e| StudioError::Server(e.to_string()))?
    };
    let thread = std::thread::Builder::new()
        .name("studio-server".into())
        .spawn(move || {
            // On stop the server future is dropped, not drained: open sockets would keep a
            // graceful shutdown waiting; dropping the runtime ends their tasks.
            runtime.block_on(async move {
                tokio::select! {
                    _ = std::future::IntoFuture::into_future(axum::serve(listener, app)) => {}
                    _ = rx => {}
                }
            });
        })
        .map_err(|e| StudioError::Server(e.to_string()))?;
    let worker = start_worker(Arc::clone(&shared));
    let host = match addr {
        SocketAddr::V6(a) => format!("[{}]:{}", a.ip(), a.port()),
        SocketAddr::V4(a) => a.to_string(),
    };
    Ok(Running {
        url: format!("http://{host}/?token={token}"),
        addr,
        token,
        shared,
        shutdown: Some(tx),
        thread: Some(thread),
        worker: Some(worker),
    })
}

async fn index() -> Response {
    asset(Path("index.html".to_owned())).await
}

async fn asset(Path(name): Path<String>) -> Response {
    match ASSETS.iter().find(|(n, _)| *n == name) {
        Some((_, bytes)) => {
            let headers = [(header::CONTENT_TYPE, content_type(&name)), (header::CACHE_CONTROL, "no-store")];
            (headers, *bytes).into_response()
        }
        None => (StatusCode::NOT_FOUND, "no such asset").into_response(),
    }
}

async fn websocket(State(state): State<AppState>, upgrade: WebSocketUpgrade) -> Response {
    upgrade
        .max_message_size(MAX_MESSAGE)
        .max_frame_size(MAX_MESSAGE)
        .on_upgrade(move |socket| socket::serve_socket(socket, state.shared))
}
