//! Where a study or a grid lives, as a user names it: an SQLite file, or a study or grid by
//! name in a PostgreSQL database.

use std::path::PathBuf;

use crate::error::{Error, Result};

/// A study's place, parsed from what a user types: a file path or `sqlite://PATH` is an
/// SQLite file (one study per file); `postgresql://USER@HOST[:PORT]/DB#STUDY` (or
/// `postgres://`) is study `STUDY` of a PostgreSQL database, which holds any number.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Location {
    /// An SQLite file.
    Sqlite(PathBuf),
    /// Study `study` in a PostgreSQL database.
    Postgres {
        /// The connection URL, without the `#STUDY` (a password in it is never shown).
        url: String,
        /// The study's name in the database.
        study: String,
    },
}

/// The URL schemes [`Location::parse`] knows, for its error message.
const SCHEMES: &str = "a file path, sqlite://PATH or postgresql://USER@HOST[:PORT]/DB";

impl Location {
    /// The location `storage` names. A database URL names its study after a `#`, or else
    /// takes `study` (a database without a study name is an error). An unknown `scheme://`
    /// is refused.
    pub fn parse(storage: &str, study: Option<&str>) -> Result<Location> {
        let Some((scheme, rest)) = storage.split_once("://") else {
            return Ok(Location::Sqlite(PathBuf::from(storage)));
        };
        match scheme {
            "sqlite" if !rest.is_empty() => Ok(Location::Sqlite(PathBuf::from(rest))),
            "postgresql" | "postgres" => {
                let (url, named) = match storage.split_once('#') {
                    Some((url, name)) => (url, Some(name)),
                    None => (storage, study),
                };
                let study = named
                    .filter(|s| !s.is_empty())
                    .ok_or_else(|| Error::InvalidValue {
                        what: format!("the study or grid name of {}", redact(url)),
                        value: "none".into(),
                        expected:
                            "given (DATABASE-URL#NAME): a database holds many studies and grids"
                                .into(),
                    })?;
                Ok(Location::Postgres {
                    url: url.to_owned(),
                    study: study.to_owned(),
                })
            }
            _ => Err(Error::InvalidValue {
                what: "the storage".into(),
                value: redact(storage),
                expected: SCHEMES.into(),
            }),
        }
    }

    /// The error of a PostgreSQL location in a cdbo built without PostgreSQL (its `postgres`
    /// feature off, as in the fuzz build).
    #[cfg(not(feature = "postgres"))]
    pub(crate) fn without_postgres(&self) -> Error {
        Error::InvalidValue {
            what: "the storage".into(),
            value: self.label().display().to_string(),
            expected: "a file path or sqlite://PATH: this cdbo was built without PostgreSQL (cargo feature `postgres`)".into(),
        }
    }

    /// How messages name it: the file, or `URL#STUDY` with any password replaced by `***`.
    pub fn label(&self) -> PathBuf {
        match self {
            Location::Sqlite(path) => path.clone(),
            Location::Postgres { url, study } => PathBuf::from(format!("{}#{study}", redact(url))),
        }
    }
}

/// `url` with the password of its `user:password@` part replaced by `***`.
pub fn redact(url: &str) -> String {
    let Some((scheme, rest)) = url.split_once("://") else {
        return url.to_owned();
    };
    let authority_end = rest.find('/').unwrap_or(rest.len());
    match rest[..authority_end].rfind('@') {
        Some(at) => match rest[..at].split_once(':') {
            Some((user, _)) => format!("{scheme}://{user}:***{}", &rest[at..]),
            None => url.to_owned(),
        },
        None => url.to_owned(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn locations_by_scheme() {
        assert_eq!(
            Location::parse("a/s.db", None).unwrap(),
            Location::Sqlite("a/s.db".into())
        );
        assert_eq!(
            Location::parse("sqlite:///tmp/s.db", None).unwrap(),
            Location::Sqlite("/tmp/s.db".into())
        );
        let pg = Location::parse("postgresql://me:secret@db.lan:5433/laps", Some("kart")).unwrap();
        assert_eq!(
            pg.label(),
            PathBuf::from("postgresql://me:***@db.lan:5433/laps#kart")
        );
        assert_eq!(
            Location::parse("postgres://me@h/db#lap", Some("other")).unwrap(),
            Location::Postgres {
                url: "postgres://me@h/db".into(),
                study: "lap".into()
            }
        );
        let e = Location::parse("postgres://me@h/db", None)
            .unwrap_err()
            .to_string();
        assert!(e.contains("study or grid name"), "{e}");
        let e = Location::parse("mysql://u:pw@h/db", Some("s"))
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("mysql://u:***@h/db") && e.contains("postgresql://"),
            "{e}"
        );
        assert!(!e.contains("pw"), "{e}");
        assert_eq!(redact("postgresql://me@h/db"), "postgresql://me@h/db");
    }
}
