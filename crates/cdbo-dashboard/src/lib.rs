//! `cdbo dashboard`: a local web page over studies and experiment folders, updated live while
//! laps arrive. The page (plain HTML and JavaScript with uPlot, all served from the binary)
//! polls a small read-only JSON API:
//!
//! - `GET /api/sources`: every study and experiment on show, with its laps and best reward;
//! - `GET /api/sources/{id}[?run=RUN]`: what the page draws for one ([`view::View`]);
//! - `GET /api/sources/{id}/map?key=KEY`: a trial (study) or run (experiment) re-driven in the
//!   simulator, its path coloured by speed ([`map::MapView`]).
//!
//! The data come through the [`store::Store`] trait; nothing is ever written. A database shown
//! whole is listed again on every `GET /api/sources`: a study or grid created in it since
//! start-up joins the list, and every source keeps its id.

pub mod map;
pub mod store;
pub mod view;

use std::collections::HashMap;
use std::net::{SocketAddr, TcpListener};
use std::path::PathBuf;
use std::sync::{Arc, PoisonError, RwLock};

use axum::Router;
use axum::extract::{Path, Query, State};
use axum::http::{StatusCode, header};
use axum::response::{IntoResponse, Json, Response};
use axum::routing::get;
use cdbo::data_path::DataPath;
use cdbo::{Error, Result};
use serde::Serialize;

use store::{Kind, Source, Store};

const INDEX_HTML: &str = include_str!("../assets/index.html");
const UPLOT_JS: &str = include_str!("../assets/uPlot.iife.min.js");
const UPLOT_CSS: &str = include_str!("../assets/uPlot.min.css");
const UPLOT_LICENSE: &str = include_str!("../assets/uPlot.LICENSE");

/// The default address: this machine only.
pub const DEFAULT_BIND: &str = "127.0.0.1:8050";

/// The sources on show and how to re-drive their laps.
pub struct Dashboard {
    /// Studies and experiments, in the order given.
    pub sources: Vec<Source>,
    /// Databases shown whole ([`store::is_database`]), whose studies and grids created later
    /// are added to the sources as they appear.
    pub databases: Vec<String>,
    /// Where they are read from.
    pub store: Box<dyn Store>,
    /// The track of the studies that record none (experiments name their own).
    pub study_track: Option<String>,
    /// The car re-driven on the map.
    pub car: String,
    /// Where tracks and cars are found by name.
    pub data: DataPath,
}

/// One line of `GET /api/sources`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SourceSummary {
    /// Its index in the list.
    pub id: usize,
    /// Study or experiment.
    pub kind: Kind,
    /// Where it lives.
    pub location: String,
    /// Laps told or driven so far.
    pub laps: usize,
    /// Best reward so far (m/s).
    pub best: Option<f64>,
    /// Why it cannot be read right now, if it cannot.
    pub error: Option<String>,
}

/// A dashboard bound to its address, ready to serve.
pub struct Bound {
    listener: TcpListener,
    app: Router,
}

impl Dashboard {
    /// Binds `addr`; a port in use or an address not of this machine is a one-line error.
    pub fn bind(mut self, addr: &str) -> Result<Bound> {
        let parsed: SocketAddr = addr.parse().map_err(|_| Error::InvalidValue {
            what: "--bind".to_owned(),
            value: addr.to_owned(),
            expected: format!("an address and port such as {DEFAULT_BIND}"),
        })?;
        let listener = TcpListener::bind(parsed).map_err(|source| Error::Io {
            path: PathBuf::from(format!("--bind {addr}")),
            source,
        })?;
        let sources = RwLock::new(std::mem::take(&mut self.sources));
        Ok(Bound {
            listener,
            app: router(Arc::new(Live {
                dashboard: self,
                sources,
            })),
        })
    }

    fn summary(&self, id: usize, source: &Source) -> SourceSummary {
        let read = match source.kind {
            Kind::Study => self.store.study(source).map(|(_, trials)| {
                let rewards: Vec<f64> = trials.iter().filter_map(|t| t.reward).collect();
                (rewards.len(), rewards.into_iter().reduce(f64::max))
            }),
            Kind::Experiment => self.store.runs(source).map(|runs| {
                (
                    runs.iter().map(|r| r.laps.len()).sum(),
                    runs.iter().map(|r| r.best_reward_mps).reduce(f64::max),
                )
            }),
        };
        let (laps, best, error) = match read {
            Ok((laps, best)) => (laps, best, None),
            Err(e) => (0, None, Some(e.to_string())),
        };
        SourceSummary {
            id,
            kind: source.kind,
            location: source.location.clone(),
            laps,
            best,
            error,
        }
    }

    fn view(
        &self,
        source: &Source,
        run: Option<&str>,
    ) -> std::result::Result<view::View, ApiError> {
        match source.kind {
            Kind::Study => {
                let (config, trials) = self.store.study(source)?;
                let mut view = view::study(&config, &trials)?;
                // The track the map drives on: the study's own, else the dashboard's --track.
                view.track = view.track.or_else(|| self.study_track.clone());
                Ok(view)
            }
            Kind::Experiment => Ok(view::experiment(&self.store.runs(source)?, run)?),
        }
    }

    fn map(&self, source: &Source, key: &str) -> std::result::Result<map::MapView, ApiError> {
        let (track, policy) = match source.kind {
            Kind::Study => {
                let (config, trials) = self.store.study(source)?;
                let track = config
                    .track
                    .clone()
                    .or_else(|| self.study_track.clone())
                    .ok_or_else(|| {
                        ApiError::Missing(
                            "the study records no track: start the dashboard with --track"
                                .to_owned(),
                        )
                    })?;
                let trial = trials
                    .into_iter()
                    .find(|t| t.id.to_string() == key)
                    .ok_or_else(|| {
                        ApiError::Missing(format!("{}: no trial {key}", source.location))
                    })?;
                let policy = config.policy(&trial.weights)?;
                (track, policy)
            }
            Kind::Experiment => {
                let run = self
                    .store
                    .runs(source)?
                    .into_iter()
                    .find(|r| r.spec.id() == key)
                    .ok_or_else(|| {
                        ApiError::Missing(format!("{}: no run {key}", source.location))
                    })?;
                let policy = run.best_policy()?;
                (run.spec.track, policy)
            }
        };
        let track = cdbo::track::catalog::find(&track, &self.data)?;
        let car = cdbo::car::catalog::find(&self.car, &self.data)?;
        Ok(map::drive(track, &car, key.to_owned(), &policy)?)
    }
}

/// A dashboard being served, with its sources so far: those given, then those its databases
/// gained since, each keeping its id (its place in the list).
struct Live {
    dashboard: Dashboard,
    sources: RwLock<Vec<Source>>,
}

impl Live {
    /// The sources now, the databases listed again: a study or grid created since is added
    /// (a database out of reach keeps its sources as they were; their reads say why).
    fn refresh(&self) -> Vec<Source> {
        let mut sources = self.sources.write().unwrap_or_else(PoisonError::into_inner);
        for database in &self.dashboard.databases {
            if let Ok(found) = self.dashboard.store.database(database, &sources) {
                sources.extend(found);
            }
        }
        sources.clone()
    }

    fn source(&self, id: usize) -> std::result::Result<Source, ApiError> {
        let sources = self.sources.read().unwrap_or_else(PoisonError::into_inner);
        sources
            .get(id)
            .cloned()
            .ok_or_else(|| ApiError::Missing(format!("no source {id}")))
    }
}

impl Bound {
    /// The address served (the port chosen when `:0` was asked for).
    pub fn local_addr(&self) -> Result<SocketAddr> {
        self.listener.local_addr().map_err(|source| Error::Io {
            path: PathBuf::from("the dashboard's socket"),
            source,
        })
    }

    /// Serves until the process ends.
    pub fn serve(self) -> Result<()> {
        let io = |source: std::io::Error| Error::Io {
            path: PathBuf::from("the dashboard's socket"),
            source,
        };
        let runtime = tokio::runtime::Builder::new_current_thread()
            .enable_io()
            .build()
            .map_err(io)?;
        runtime.block_on(async move {
            self.listener.set_nonblocking(true).map_err(io)?;
            let listener = tokio::net::TcpListener::from_std(self.listener).map_err(io)?;
            axum::serve(listener, self.app).await.map_err(io)
        })
    }
}

/// A failed request as a response, with a JSON body `{"error": "…"}`: 404 for what does not
/// exist, 500 for a read that failed.
enum ApiError {
    /// No such source, trial or run, or no track to drive on.
    Missing(String),
    /// The read or the re-drive failed.
    Failed(Error),
}

impl From<Error> for ApiError {
    fn from(e: Error) -> ApiError {
        ApiError::Failed(e)
    }
}

impl IntoResponse for ApiError {
    fn into_response(self) -> Response {
        let (status, text) = match self {
            ApiError::Missing(text) => (StatusCode::NOT_FOUND, text),
            ApiError::Failed(e @ (Error::NoStudy { .. } | Error::NotFound { .. })) => {
                (StatusCode::NOT_FOUND, e.to_string())
            }
            ApiError::Failed(e) => (StatusCode::INTERNAL_SERVER_ERROR, e.to_string()),
        };
        (status, Json(serde_json::json!({ "error": text }))).into_response()
    }
}

type ApiResult<T> = std::result::Result<Json<T>, ApiError>;

/// Runs a read on the blocking pool (SQLite and the simulator block).
async fn blocking<T: Send + 'static>(
    f: impl FnOnce() -> std::result::Result<T, ApiError> + Send + 'static,
) -> ApiResult<T> {
    match tokio::task::spawn_blocking(f).await {
        Ok(Ok(v)) => Ok(Json(v)),
        Ok(Err(e)) => Err(e),
        Err(_) => Err(ApiError::Failed(Error::Panicked("a dashboard request"))),
    }
}

fn router(live: Arc<Live>) -> Router {
    let asset = |mime: &'static str, body: &'static str| {
        move || async move { ([(header::CONTENT_TYPE, mime)], body) }
    };
    Router::new()
        .route("/", get(asset("text/html; charset=utf-8", INDEX_HTML)))
        .route("/uplot.js", get(asset("text/javascript", UPLOT_JS)))
        .route("/uplot.css", get(asset("text/css", UPLOT_CSS)))
        .route(
            "/licenses/uplot",
            get(asset("text/plain; charset=utf-8", UPLOT_LICENSE)),
        )
        .route("/api/sources", get(sources))
        .route("/api/sources/{id}", get(source_view))
        .route("/api/sources/{id}/map", get(source_map))
        .with_state(live)
}

async fn sources(State(live): State<Arc<Live>>) -> ApiResult<Vec<SourceSummary>> {
    blocking(move || {
        Ok(live
            .refresh()
            .iter()
            .enumerate()
            .map(|(id, s)| live.dashboard.summary(id, s))
            .collect())
    })
    .await
}

async fn source_view(
    State(live): State<Arc<Live>>,
    Path(id): Path<usize>,
    Query(q): Query<HashMap<String, String>>,
) -> ApiResult<view::View> {
    blocking(move || {
        let source = live.source(id)?;
        live.dashboard
            .view(&source, q.get("run").map(String::as_str))
    })
    .await
}

async fn source_map(
    State(live): State<Arc<Live>>,
    Path(id): Path<usize>,
    Query(q): Query<HashMap<String, String>>,
) -> ApiResult<map::MapView> {
    let key = q.get("key").cloned().unwrap_or_default();
    blocking(move || live.dashboard.map(&live.source(id)?, &key)).await
}
