//! One tab's WebSocket (docs/studio.md, "Protocol"): text messages in, replies and the engine's
//! broadcasts out (an image as its JSON header, then the PNG as one binary message). A tab too
//! slow for the broadcast queue gets the whole current state instead of what it missed.

use super::handle::{current, handle};
use crate::engine::Shared;
use crate::protocol::{Envelope, Outbound};
use axum::extract::ws::{Message, WebSocket};
use std::sync::Arc;
use tokio::sync::broadcast::error::RecvError;

async fn send(socket: &mut WebSocket, message: Outbound) -> bool {
    match message {
        Outbound::Text(text) => socket.send(Message::Text(text.into())).await.is_ok(),
        Outbound::Image { header, png } => {
            socket.send(Message::Text(header.into())).await.is_ok()
                && socket.send(Message::Binary(png.into())).await.is_ok()
        }
    }
}

/// Serves one socket until it closes.
pub async fn serve_socket(mut socket: WebSocket, shared: Arc<Shared>) {
    let mut broadcasts = shared.out.subscribe();
    loop {
        tokio::select! {
            incoming = socket.recv() => {
                let text = match incoming {
                    Some(Ok(Message::Text(text))) => text,
                    Some(Ok(Message::Binary(_))) => {
                        let reply = Outbound::error(None, "the studio takes JSON text messages only");
                        if !send(&mut socket, reply).await { return; }
                        continue;
                    }
                    Some(Ok(_)) => continue,
                    Some(Err(_)) | None => return,
                };
                let replies = match Envelope::parse(text.as_str()) {
                    Ok(envelope) => {
                        let shared = Arc::clone(&shared);
                        tokio::task::spawn_blocking(move || handle(&shared, envelope))
                            .await
                            .unwrap_or_else(|_| vec![Outbound::error(None, "the request failed inside the studio")])
                    }
                    Err((id, message)) => vec![Outbound::error(id, message)],
                };
                for reply in replies {
                    if !send(&mut socket, reply).await { return; }
                }
            }
            outgoing = broadcasts.recv() => {
                match outgoing {
                    Ok(message) => if !send(&mut socket, message).await { return; },
                    // The queue dropped messages for this tab: what is left of it may not hold
                    // the last map or state, so skip it and send the whole current state
                    // (taken after resubscribing: anything newer follows in the queue).
                    Err(RecvError::Lagged(_)) => {
                        broadcasts = broadcasts.resubscribe();
                        for message in current(&shared, None) {
                            if !send(&mut socket, message).await { return; }
                        }
                    }
                    Err(RecvError::Closed) => return,
                }
            }
        }
    }
}
