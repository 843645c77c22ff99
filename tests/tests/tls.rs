//! Optional TLS (feature `tls`): a pool that trusts the worker's certificate works, with the
//! token still checked; a plaintext pool cannot talk to a TLS worker.

mod common;
use common::*;
use cosdem_pool::{ClientTls, Pool, PoolConfig, PoolError};
use cosdem_worker::{StandIn, TlsIdentity, Token, WorkerConfig};

#[test]
fn tls_worker_and_pool() {
    let ck = rcgen::generate_simple_self_signed(vec!["localhost".to_string()]).unwrap();
    let cert_pem = ck.cert.pem().into_bytes();
    let identity = TlsIdentity {
        cert_pem: cert_pem.clone(),
        key_pem: ck.key_pair.serialize_pem().into_bytes(),
    };
    let token = Token::new("tls-token").unwrap();
    let rt = tokio::runtime::Runtime::new().unwrap();
    let config =
        WorkerConfig { tls: Some(identity), token: Some(token.clone()), ..Default::default() };
    let addr = rt.block_on(start_worker(config, StandIn::new())).to_string();

    let tls = ClientTls { ca_pem: cert_pem, domain: "localhost".into() };
    let good = PoolConfig { tls: Some(tls.clone()), token: Some(token), ..test_config() };
    let mut pool = Pool::connect(std::slice::from_ref(&addr), good).unwrap();
    create(&mut pool, 10, 1);
    assert_identical(&reference(10, 1), &run_program(&mut pool, &mut |_, _| {}));
    drop(pool);

    let plain = PoolConfig { token: Some(Token::new("tls-token").unwrap()), ..test_config() };
    let Err(e) = Pool::connect(std::slice::from_ref(&addr), plain) else {
        panic!("a plaintext pool talked to a TLS worker");
    };
    // A plaintext HTTP/2 connection to a TLS port is accepted, then fails in the HTTP/2
    // exchange, so it is a refusal naming the worker (not skipped as unreachable). Its code
    // depends on when the TLS side hangs up (Unknown "transport error", Internal "h2 protocol
    // error" and Cancelled seen), but it is never the token check's.
    assert!(
        matches!(&e, PoolError::Refused { worker, code, .. }
            if *worker == addr && *code != tonic::Code::Unauthenticated),
        "{e}"
    );
    let no_token = PoolConfig { tls: Some(tls), ..test_config() };
    let Err(e) = Pool::connect(std::slice::from_ref(&addr), no_token) else {
        panic!("a pool without the token was accepted");
    };
    // Over TLS the worker answers, and refuses the call for want of the token.
    assert!(
        matches!(&e, PoolError::Refused { worker, code: tonic::Code::Unauthenticated, .. } if *worker == addr),
        "{e}"
    );
}
