//! What the health service reports: SERVING while the worker accepts connections and is not
//! draining, NOT_SERVING otherwise (out of descriptors, every connection slot taken, or after
//! the shutdown signal), for `""` and `yat.render.v1.RenderNode` alike.

use std::sync::atomic::{AtomicBool, Ordering};

use tonic::server::NamedService;
use tonic_health::server::HealthReporter;
use tonic_health::ServingStatus;

use crate::grpc::RenderService;

pub struct Availability {
    reporter: HealthReporter,
    accepting: AtomicBool,
    draining: AtomicBool,
    /// Held while a status is published, so the last one published is the latest state.
    publishing: tokio::sync::Mutex<()>,
}

impl Availability {
    /// Starts SERVING.
    pub async fn new(reporter: HealthReporter) -> Self {
        let availability = Self {
            reporter,
            accepting: AtomicBool::new(true),
            draining: AtomicBool::new(false),
            publishing: tokio::sync::Mutex::new(()),
        };
        availability.publish().await;
        availability
    }

    /// Whether the worker can accept connections now; published only when it changes.
    pub async fn set_accepting(&self, accepting: bool) {
        if self.accepting.swap(accepting, Ordering::AcqRel) != accepting {
            self.publish().await;
        }
    }

    /// The worker is draining: NOT_SERVING from now on.
    pub async fn drain(&self) {
        self.draining.store(true, Ordering::Release);
        self.publish().await;
    }

    async fn publish(&self) {
        let _one = self.publishing.lock().await;
        let serving =
            self.accepting.load(Ordering::Acquire) && !self.draining.load(Ordering::Acquire);
        let status = if serving {
            ServingStatus::Serving
        } else {
            ServingStatus::NotServing
        };
        for service in ["", RenderService::NAME] {
            self.reporter.set_service_status(service, status).await;
        }
    }
}
