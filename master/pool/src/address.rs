//! Worker addresses: the form of each (`host:port`) checked before any lookup, and their
//! resolution (a name may stand for several workers), bounded in time.

use crate::PoolError;
use std::net::SocketAddr;
use std::time::Duration;

/// Checks the form of a worker address (`host:port`, `ipv4:port`, `[ipv6]:port`) before any
/// name is looked up: an address that has none is a configuration error naming it (not a
/// worker that did not answer).
pub(crate) fn check_address(address: &str) -> Result<(), PoolError> {
    if address.parse::<SocketAddr>().is_ok() {
        return Ok(());
    }
    let bad = |why: String| {
        Err(PoolError::Config(format!(
            "worker address {address:?}: {why} (expected host:port, e.g. 127.0.0.1:7700, \
             worker-0:7700 or [::1]:7700)"
        )))
    };
    let Some((host, port)) = address.rsplit_once(':') else {
        return bad("no port".into());
    };
    if port.parse::<u16>().is_err() {
        return bad(format!("port {port:?} is not a number from 0 to 65535"));
    }
    if host.is_empty() {
        return bad("no host".into());
    }
    if host.starts_with('[') || host.contains(':') {
        return bad("not an IPv6 address in brackets".into());
    }
    let label = |l: &str| {
        !l.is_empty()
            && !l.starts_with('-')
            && l.chars().all(|c| c.is_ascii_alphanumeric() || c == '-' || c == '_')
    };
    if !host.trim_end_matches('.').split('.').all(label) {
        return bad(format!("host {host:?} is not a host name"));
    }
    Ok(())
}

/// The addresses `source` resolves to, within `timeout` (a name whose DNS server does not
/// answer must not stall the run: the lookup itself goes on in a blocking thread, abandoned).
pub(crate) async fn resolve(source: &str, timeout: Duration) -> Vec<SocketAddr> {
    match tokio::time::timeout(timeout, tokio::net::lookup_host(source)).await {
        Ok(Ok(addrs)) => {
            let mut v: Vec<_> = addrs.collect();
            v.sort();
            v.dedup();
            v
        }
        Ok(Err(e)) => {
            tracing::warn!(source, error = %e, "cannot resolve worker address");
            Vec::new()
        }
        Err(_) => {
            tracing::warn!(source, ?timeout, "worker address not resolved in time");
            Vec::new()
        }
    }
}

/// Resolves every source concurrently, each within `timeout`; sorted, without duplicates.
pub(crate) async fn resolve_all(sources: &[String], timeout: Duration) -> Vec<SocketAddr> {
    let mut set = tokio::task::JoinSet::new();
    for s in sources {
        let s = s.clone();
        set.spawn(async move { resolve(&s, timeout).await });
    }
    let mut out = Vec::new();
    while let Some(r) = set.join_next().await {
        out.extend(r.unwrap_or_default());
    }
    out.sort();
    out.dedup();
    out
}
