//! The shared secret: a worker refuses calls without the right token (UNAUTHENTICATED), a
//! pool with the right one works, and a worker will not listen publicly without a token.

mod common;
use common::*;
use cosdem_pool::{Pool, PoolConfig, PoolError};
use cosdem_proto::PROTOCOL_VERSION;
use cosdem_proto::v1 as pb;
use cosdem_worker::{StandIn, Token, WorkerConfig};
use tonic::Code;

#[tokio::test]
async fn missing_or_wrong_token_is_unauthenticated() {
    let config =
        WorkerConfig { token: Some(Token::new("s3cret-token").unwrap()), ..Default::default() };
    let addr = start_worker(config, StandIn::new()).await;
    let mut c = client(addr).await;
    let hs = || pb::HandshakeRequest {
        protocol_version: PROTOCOL_VERSION,
        master_build_id: String::new(),
    };
    let e = c.handshake(hs()).await.unwrap_err();
    assert_eq!(e.code(), Code::Unauthenticated);
    let mut req = tonic::Request::new(hs());
    req.metadata_mut().insert("authorization", "Bearer nope".parse().unwrap());
    assert_eq!(c.handshake(req).await.unwrap_err().code(), Code::Unauthenticated);
    let mut req = tonic::Request::new(hs());
    req.metadata_mut().insert("authorization", "Bearer s3cret-token".parse().unwrap());
    c.handshake(req).await.unwrap();
}

#[test]
fn pool_with_wrong_token_is_refused_and_with_the_right_one_works() {
    let env = [("COSDEM_TOKEN", "tok-123")];
    let w = WorkerProcess::start(&[], &env);
    let addrs = vec![w.addr.to_string()];
    let err = Pool::connect(&addrs, test_config()).err().expect("refused without a token");
    assert!(matches!(err, PoolError::Refused { code: Code::Unauthenticated, .. }), "{err}");
    let wrong = PoolConfig { token: Some(Token::new("tok-999").unwrap()), ..test_config() };
    let err = Pool::connect(&addrs, wrong).err().expect("refused with a wrong token");
    assert!(matches!(err, PoolError::Refused { code: Code::Unauthenticated, .. }), "{err}");
    assert!(!err.to_string().contains("tok-"), "the token is never shown: {err}");
    let right = PoolConfig { token: Some(Token::new("tok-123").unwrap()), ..test_config() };
    let mut pool = Pool::connect(&addrs, right).unwrap();
    create(&mut pool, 10, 1);
    let trace = run_program(&mut pool, &mut |_, _| {});
    assert_identical(&reference(10, 1), &trace);
}

#[test]
fn in_process_workers_use_the_token_too() {
    let config = PoolConfig { token: Some(Token::new("abc").unwrap()), ..test_config() };
    let mut pool = standin_pool(2, config);
    create(&mut pool, 10, 1);
    assert_identical(&reference(10, 1), &run_program(&mut pool, &mut |_, _| {}));
}

#[test]
fn public_address_without_token_is_refused() {
    let config = WorkerConfig { listen: "0.0.0.0:0".parse().unwrap(), ..Default::default() };
    let err = config.validate().unwrap_err().to_string();
    assert!(err.contains("without a token"), "{err}");
    assert!(format!("{:?}", Token::new("hidden").unwrap()).contains("redacted"));
}

#[test]
fn pool_without_token_refuses_public_workers() {
    let err = Pool::connect(&["10.255.255.1:50051".to_string()], test_config()).err().unwrap();
    assert!(matches!(err, PoolError::Config(_)), "{err}");
    assert!(err.to_string().contains("token is required"), "{err}");
}
