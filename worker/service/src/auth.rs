//! The shared secret: loaded from `--token-file` or `COSDEM_TOKEN`, sent as
//! `authorization: Bearer <token>`, checked on every MicroSolver call. Never logged.

use super::error::{Result, ServiceError};
use std::fmt;
use std::path::Path;
use std::sync::Arc;
use tonic::metadata::MetadataValue;
use tonic::{Request, Status};

/// Environment variable holding the token when no file is given.
pub const TOKEN_ENV: &str = "COSDEM_TOKEN";

/// A shared secret. `Debug` and `Display` never show it.
#[derive(Clone, PartialEq, Eq)]
pub struct Token(Arc<str>);

impl fmt::Debug for Token {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("Token(<redacted>)")
    }
}

impl Token {
    /// A token from its text (surrounding whitespace trimmed; empty is refused).
    pub fn new(secret: &str) -> Result<Self> {
        let s = secret.trim();
        if s.is_empty() {
            return Err(ServiceError::Config("empty token".into()));
        }
        if s.chars().any(|c| !c.is_ascii_graphic()) {
            return Err(ServiceError::Config(
                "token must be printable ASCII without spaces".into(),
            ));
        }
        Ok(Token(s.into()))
    }

    /// The token from `file` if given, else from `COSDEM_TOKEN`, else none.
    pub fn load(file: Option<&Path>) -> Result<Option<Self>> {
        if let Some(path) = file {
            let text = std::fs::read_to_string(path)
                .map_err(|e| ServiceError::Config(format!("token file {}: {e}", path.display())))?;
            return Token::new(&text).map(Some);
        }
        match std::env::var(TOKEN_ENV) {
            Ok(v) if !v.trim().is_empty() => Token::new(&v).map(Some),
            _ => Ok(None),
        }
    }

    /// The metadata value a client sends.
    pub fn header(&self) -> MetadataValue<tonic::metadata::Ascii> {
        format!("Bearer {}", self.0).parse().expect("token is printable ASCII")
    }

    fn matches(&self, presented: &[u8]) -> bool {
        let expected = self.0.as_bytes();
        // Constant time in the content (the length is not secret enough to matter).
        presented.len() == expected.len()
            && presented.iter().zip(expected).fold(0u8, |acc, (a, b)| acc | (a ^ b)) == 0
    }
}

/// Server side: refuses calls without the right token (UNAUTHENTICATED).
#[derive(Clone, Debug)]
pub struct CheckToken(pub Option<Token>);

impl tonic::service::Interceptor for CheckToken {
    fn call(&mut self, req: Request<()>) -> Result<Request<()>, Status> {
        let Some(token) = &self.0 else { return Ok(req) };
        let presented = req
            .metadata()
            .get(cosdem_proto::AUTHORIZATION)
            .and_then(|v| v.as_bytes().strip_prefix(b"Bearer "));
        match presented {
            Some(p) if token.matches(p) => Ok(req),
            Some(_) => Err(Status::unauthenticated("wrong token")),
            None => Err(Status::unauthenticated("missing token (authorization: Bearer ...)")),
        }
    }
}

/// Client side: attaches the token to every call.
#[derive(Clone, Debug)]
pub struct AttachToken(pub Option<Token>);

impl tonic::service::Interceptor for AttachToken {
    fn call(&mut self, mut req: Request<()>) -> Result<Request<()>, Status> {
        if let Some(token) = &self.0 {
            req.metadata_mut().insert(cosdem_proto::AUTHORIZATION, token.header());
        }
        Ok(req)
    }
}
