//! An error and its causes in one line, as the command line prints them
//! (`error: {e:#}`): for messages that go where no error chain is kept (a
//! Python exception, a run log's event).

use std::error::Error;
use std::fmt::Write;

/// `e`'s message followed by each cause's, joined by `": "`; a cause whose
/// words the message already holds is not repeated.
pub fn error_chain(e: &dyn Error) -> String {
    let mut msg = e.to_string();
    let mut source = e.source();
    while let Some(s) = source {
        let text = s.to_string();
        if !msg.contains(&text) {
            let _ = write!(msg, ": {text}");
        }
        source = s.source();
    }
    msg
}

/// The operating system's error inside `e`, without the words a library
/// wrapped round it (tempfile appends the temporary path it tried): what
/// a caller that names the user's own path reports. The innermost
/// `io::Error` with an OS code, else one of `e`'s kind.
pub fn os_error(e: std::io::Error) -> std::io::Error {
    let mut inner: Option<&(dyn Error + 'static)> = e.get_ref().map(|r| r as _);
    while let Some(err) = inner {
        if let Some(code) = err
            .downcast_ref::<std::io::Error>()
            .and_then(std::io::Error::raw_os_error)
        {
            return std::io::Error::from_raw_os_error(code);
        }
        inner = err.source();
    }
    match e.raw_os_error() {
        Some(code) => std::io::Error::from_raw_os_error(code),
        None => std::io::Error::from(e.kind()),
    }
}

/// Whether `dir` is a folder one can look into, as the operating system
/// says it (`No such file or directory (os error 2)`, `Not a directory (os
/// error 20)`): checked before a library that words its errors its own way
/// (tempfile) is asked to make something in it.
pub fn check_dir(dir: &std::path::Path) -> std::io::Result<()> {
    // The trailing separator makes a file in the way "not a directory".
    std::fs::metadata(dir.join("")).map(|_| ())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Debug)]
    struct Outer(std::io::Error);
    impl std::fmt::Display for Outer {
        fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
            f.write_str("drive.mcap")
        }
    }
    impl Error for Outer {
        fn source(&self) -> Option<&(dyn Error + 'static)> {
            Some(&self.0)
        }
    }

    #[test]
    fn causes_follow_the_message_once() {
        let io = std::io::Error::new(std::io::ErrorKind::NotFound, "no such file");
        assert_eq!(error_chain(&Outer(io)), "drive.mcap: no such file");
        let plain = std::io::Error::other("alone");
        assert_eq!(error_chain(&plain), "alone");
    }
}
