//! Which trial a worker drives: claims with an owner and a lease, as Optuna's RDB storage keeps
//! RUNNING trials with a heartbeat and a grace period. The rules here know nothing of the
//! storage (SQLite or PostgreSQL): the storage lists the pending trials with their claims
//! inside one transaction, and [`hand_out`] decides. The cells of an experiment grid spread
//! over workers ([`crate::experiment::shared`]) are handed out by the same rules, a cell
//! standing for a trial; [`while_renewing`] keeps either claimed while it runs.
//!
//! - A worker that asks again gets its own pending trial back (a restarted `optimize` with
//!   the same worker id, or a retry after an error).
//! - A pending trial nobody holds — never claimed (asked by hand with `cdbo study ask`), its
//!   lease run out (no heartbeat for a whole lease), or its owner a process on this host that
//!   no longer exists (killed) — is handed to the asking worker.
//! - Otherwise, while the study has fewer told plus pending trials than the worker's total,
//!   the worker gets a new suggestion, made on a copy of the optimiser told every pending
//!   trial's weights with a constant lie (the lowest reward told so far): a distinct point
//!   away from the laps in flight, never the same weights.
//! - Once told plus pending trials reach the total, the worker waits: the laps in flight will
//!   be told, or handed out again when their lease runs out.

use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

use crate::error::Error;

/// A process driving laps for a study.
#[derive(Debug, Clone, PartialEq)]
pub struct Worker {
    /// `HOST/PID/START`: unique across hosts, processes and restarts.
    pub id: String,
    /// How long a claim stays valid without a heartbeat.
    pub lease: Duration,
}

/// The lease a worker gets unless it asks for another: a lap of a real car takes minutes, and
/// a worker renews its claim every [`Worker::heartbeat_interval`] while it drives.
pub const DEFAULT_LEASE: Duration = Duration::from_secs(60);

impl Worker {
    /// This process as a worker.
    pub fn this_process(lease: Duration) -> Worker {
        let start = std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map_or(0, |d| d.as_nanos());
        Worker {
            id: format!("{}/{}/{start}", host_name(), std::process::id()),
            lease,
        }
    }

    /// How often a driving worker renews its claim: six times per lease, so that a few late
    /// heartbeats do not lose it.
    pub fn heartbeat_interval(&self) -> Duration {
        self.lease / 6
    }
}

/// A pending trial's claim, as the storage holds it.
#[derive(Debug, Clone, PartialEq)]
pub struct Claim {
    /// The trial.
    pub trial: i64,
    /// The worker holding it, if any.
    pub owner: Option<String>,
    /// Unix time (s) until which the claim holds without another heartbeat.
    pub lease_until: Option<f64>,
}

/// What a worker is to do next.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Handout {
    /// Drive this pending trial (its own, or one nobody holds).
    Pending(i64),
    /// Drive a new suggestion.
    New,
    /// Every remaining trial is out with another live worker: wait and ask again.
    Wait,
    /// The study has told its total.
    Done,
}

/// The decision for worker `me` at unix time `now`, given the pending trials' claims in trial
/// order, the number of told trials and the total the worker drives to (`None`: no limit).
pub fn hand_out(
    pending: &[Claim],
    told: usize,
    total: Option<usize>,
    me: &Worker,
    now: f64,
) -> Handout {
    if total.is_some_and(|t| told >= t) {
        return Handout::Done;
    }
    if let Some(c) = pending
        .iter()
        .find(|c| c.owner.as_deref() == Some(me.id.as_str()))
    {
        return Handout::Pending(c.trial);
    }
    if let Some(c) = pending.iter().find(|c| is_free(c, now)) {
        return Handout::Pending(c.trial);
    }
    if total.is_some_and(|t| told + pending.len() >= t) {
        return Handout::Wait;
    }
    Handout::New
}

/// Nobody holds the claim: never claimed, its lease run out, or its owner gone.
pub fn is_free(claim: &Claim, now: f64) -> bool {
    match &claim.owner {
        None => true,
        Some(owner) => claim.lease_until.is_none_or(|t| t < now) || owner_is_gone(owner),
    }
}

/// The owner `HOST/PID/START` is a process of this host that no longer exists.
fn owner_is_gone(owner: &str) -> bool {
    let mut parts = owner.split('/');
    let (Some(host), Some(pid)) = (parts.next(), parts.next()) else {
        return false;
    };
    let Ok(pid) = pid.parse::<u32>() else {
        return false;
    };
    host == host_name() && pid != std::process::id() && !process_exists(pid)
}

/// Whether process `pid` of this host exists (on other systems than Unix: assumed so).
#[cfg(unix)]
pub fn process_exists(pid: u32) -> bool {
    let Ok(pid) = libc::pid_t::try_from(pid) else {
        return true;
    };
    // SAFETY: signal 0 only checks that the process exists; nothing is sent.
    let r = unsafe { libc::kill(pid, 0) };
    r == 0 || std::io::Error::last_os_error().raw_os_error() != Some(libc::ESRCH)
}

/// Whether process `pid` of this host exists (on other systems than Unix: assumed so).
#[cfg(not(unix))]
pub fn process_exists(_pid: u32) -> bool {
    true
}

fn host_name() -> String {
    crate::bounded::read_text(
        std::path::Path::new("/proc/sys/kernel/hostname"),
        &crate::bounded::SYSTEM_LINE,
    )
    .map(|h| h.trim().replace('/', "_"))
    .ok()
    .filter(|h| !h.is_empty())
    .unwrap_or_else(|| "localhost".into())
}

/// The constant lie told for a lap in flight: the lowest reward told so far (0, a failed lap,
/// before any), so that the fantasy pushes the next suggestion away from it.
pub fn lie(told_rewards: impl IntoIterator<Item = f64>) -> f64 {
    told_rewards
        .into_iter()
        .fold(None, |m: Option<f64>, r| Some(m.map_or(r, |m| m.min(r))))
        .unwrap_or(0.0)
}

/// What the heartbeat met while the work ran.
#[derive(Debug)]
pub enum Missed {
    /// The claim ran out and another worker took the trial (or cell) over, or it was told.
    Lost,
    /// A renewal failed (the work goes on; the next beat retries).
    Failed(Error),
}

/// Runs `work` while a thread renews a claim every `interval`: `renewer` opens the thread's
/// own connection, at the first beat (work shorter than one interval opens none), and returns
/// the renewal (true while the claim is still ours). Returns the work's result and what the
/// heartbeat met; it stops at the first lost claim.
pub fn while_renewing<'a, T>(
    interval: Duration,
    renewer: impl FnOnce() -> crate::Result<Box<dyn FnMut() -> crate::Result<bool> + 'a>> + Send + 'a,
    work: impl FnOnce() -> T,
) -> (T, Vec<Missed>) {
    let stop = AtomicBool::new(false);
    std::thread::scope(|scope| {
        let beat = scope.spawn(|| {
            let mut missed = Vec::new();
            std::thread::park_timeout(interval);
            if stop.load(Ordering::Acquire) {
                return missed;
            }
            let mut renew = match renewer() {
                Ok(r) => r,
                Err(e) => {
                    missed.push(Missed::Failed(e));
                    return missed;
                }
            };
            loop {
                match renew() {
                    Ok(true) => {}
                    Ok(false) => {
                        missed.push(Missed::Lost);
                        return missed;
                    }
                    Err(e) => missed.push(Missed::Failed(e)),
                }
                std::thread::park_timeout(interval);
                if stop.load(Ordering::Acquire) {
                    return missed;
                }
            }
        });
        let result = work();
        stop.store(true, Ordering::Release);
        beat.thread().unpark();
        let missed = beat.join().unwrap_or_default();
        (result, missed)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn worker(id: &str) -> Worker {
        Worker {
            id: id.into(),
            lease: Duration::from_secs(10),
        }
    }

    fn claim(trial: i64, owner: Option<&str>, until: f64) -> Claim {
        Claim {
            trial,
            owner: owner.map(String::from),
            lease_until: Some(until),
        }
    }

    #[test]
    fn workers_get_their_own_then_free_then_new_trials() {
        let me = worker("elsewhere/1/1");
        // Nothing pending: a new trial, until the total is reached.
        assert_eq!(hand_out(&[], 3, Some(10), &me, 0.0), Handout::New);
        assert_eq!(hand_out(&[], 10, Some(10), &me, 0.0), Handout::Done);
        assert_eq!(hand_out(&[], 10, None, &me, 0.0), Handout::New);
        // Another live worker's trial is not mine: a new one beside it.
        let other = claim(4, Some("elsewhere/2/2"), 100.0);
        assert_eq!(
            hand_out(std::slice::from_ref(&other), 3, Some(10), &me, 50.0),
            Handout::New
        );
        // ... unless it is the last one to reach the total: wait for it.
        assert_eq!(
            hand_out(std::slice::from_ref(&other), 9, Some(10), &me, 50.0),
            Handout::Wait
        );
        // Its lease runs out: it is handed out again.
        assert_eq!(
            hand_out(std::slice::from_ref(&other), 9, Some(10), &me, 150.0),
            Handout::Pending(4)
        );
        // My own comes first; an unclaimed one (asked by hand) is anyone's.
        let mine = claim(5, Some("elsewhere/1/1"), 100.0);
        assert_eq!(
            hand_out(&[other.clone(), mine], 3, Some(10), &me, 50.0),
            Handout::Pending(5)
        );
        let unclaimed = claim(6, None, 0.0);
        assert_eq!(
            hand_out(&[other, unclaimed], 3, Some(10), &me, 50.0),
            Handout::Pending(6)
        );
    }

    #[test]
    fn a_dead_process_on_this_host_loses_its_claim_at_once() {
        let mut child = std::process::Command::new("true").spawn().unwrap();
        let pid = child.id();
        child.wait().unwrap();
        let dead = format!("{}/{pid}/0", host_name());
        assert!(owner_is_gone(&dead));
        assert!(!owner_is_gone(&format!(
            "{}/{}/0",
            host_name(),
            std::process::id()
        )));
        assert!(!owner_is_gone(&format!("another-host/{pid}/0")));
        let c = claim(1, Some(&dead), 1e12);
        assert!(is_free(&c, 0.0));
    }

    #[test]
    fn the_heartbeat_connects_at_its_first_beat_and_stops_at_a_lost_claim() {
        use std::sync::atomic::AtomicUsize;
        let interval = Duration::from_millis(40);
        let (opened, beats) = (AtomicUsize::new(0), AtomicUsize::new(0));
        let renewer = || -> crate::Result<Box<dyn FnMut() -> crate::Result<bool> + '_>> {
            opened.fetch_add(1, Ordering::SeqCst);
            Ok(Box::new(|| Ok(beats.fetch_add(1, Ordering::SeqCst) < 2)))
        };
        // Shorter than one interval: no connection, no beat.
        let (v, missed) = while_renewing(interval, renewer, || 7);
        assert_eq!((v, missed.len()), (7, 0));
        assert_eq!(opened.load(Ordering::SeqCst), 0);
        // Long work: one connection, two renewals, then the claim is lost and beats stop.
        let renewer = || -> crate::Result<Box<dyn FnMut() -> crate::Result<bool> + '_>> {
            opened.fetch_add(1, Ordering::SeqCst);
            Ok(Box::new(|| Ok(beats.fetch_add(1, Ordering::SeqCst) < 2)))
        };
        let ((), missed) = while_renewing(interval, renewer, || std::thread::sleep(interval * 25));
        assert_eq!(opened.load(Ordering::SeqCst), 1);
        assert_eq!(beats.load(Ordering::SeqCst), 3);
        assert!(matches!(missed.as_slice(), [Missed::Lost]), "{missed:?}");
    }

    #[test]
    fn the_lie_is_the_lowest_reward() {
        assert_eq!(lie([3.0, 1.5, 2.0]), 1.5);
        assert_eq!(lie([]), 0.0);
    }
}
