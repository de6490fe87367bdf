//! A response body fed line by line from a solve thread (NDJSON): the solve sends each line
//! into a bounded channel as it is computed; when the client goes away hyper drops the body,
//! the channel closes and the solve's next send fails, which stops the solve.

use std::convert::Infallible;
use std::pin::Pin;
use std::task::{Context, Poll};

use axum::body::Bytes;
use http_body::Frame;
use tokio::sync::mpsc;

/// Lines still to send: those already received, then the channel until it closes.
pub struct ChannelBody {
    first: Vec<Bytes>,
    rx: mpsc::Receiver<Bytes>,
}

impl ChannelBody {
    /// `first` (lines received before the response was started), then `rx`.
    pub fn new(first: Vec<Bytes>, rx: mpsc::Receiver<Bytes>) -> ChannelBody {
        ChannelBody { first, rx }
    }
}

impl http_body::Body for ChannelBody {
    type Data = Bytes;
    type Error = Infallible;

    fn poll_frame(
        mut self: Pin<&mut Self>,
        cx: &mut Context<'_>,
    ) -> Poll<Option<Result<Frame<Bytes>, Infallible>>> {
        if !self.first.is_empty() {
            let b = self.first.remove(0);
            return Poll::Ready(Some(Ok(Frame::data(b))));
        }
        self.rx.poll_recv(cx).map(|o| o.map(|b| Ok(Frame::data(b))))
    }
}
