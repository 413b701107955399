//! Application-instance certificates and trust lists, laid out as
//! async-opcua (and most OPC UA stacks) expect: per application a folder
//! with `own/cert.der`, `private/private.pem`, `trusted/` and `rejected/`.
//!
//! `autoshovel pki init DIR` makes `DIR/plc` and `DIR/workstation`, each
//! trusting the other, and the operator's password file; `autoshovel pki
//! trust` adds a peer's certificate to a trust list. A certificate a peer
//! presents that is not in the trust list is refused and copied to
//! `rejected/`, from where a person moves it to `trusted/` after checking it.

use std::fs;
use std::path::{Path, PathBuf};

use opcua::crypto::{CertificateStore, X509Data, X509};
use opcua::types::ApplicationDescription;
use rand::Rng;

use crate::error::LinkError;

/// The two applications of the link.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Role {
    /// The PLC (or `plc-sim`): the OPC UA server.
    Plc,
    /// The workstation (`drive`): the OPC UA client.
    Workstation,
}

impl Role {
    /// Folder name under the PKI root.
    pub fn dir_name(self) -> &'static str {
        match self {
            Role::Plc => "plc",
            Role::Workstation => "workstation",
        }
    }

    /// The application URI in the certificate.
    pub fn application_uri(self) -> &'static str {
        match self {
            Role::Plc => "urn:autoshovel:plc-sim",
            Role::Workstation => "urn:autoshovel:workstation",
        }
    }

    /// The application name.
    pub fn application_name(self) -> &'static str {
        match self {
            Role::Plc => "autoshovel plc-sim",
            Role::Workstation => "autoshovel workstation",
        }
    }

    /// The other end.
    pub fn peer(self) -> Role {
        match self {
            Role::Plc => Role::Workstation,
            Role::Workstation => Role::Plc,
        }
    }
}

/// Name of the operator's password file under the PKI root.
pub const PASSWORD_FILE: &str = "operator.password";
/// The user name `pki init` sets up.
pub const OPERATOR: &str = "operator";

fn pki_err(path: &Path, why: impl Into<String>) -> LinkError {
    LinkError::Pki {
        path: path.to_path_buf(),
        why: why.into(),
    }
}

fn pki_io(path: &Path, source: std::io::Error) -> LinkError {
    LinkError::PkiIo {
        path: path.to_path_buf(),
        source,
    }
}

/// The folder of `role` under `root`.
pub fn role_dir(root: &Path, role: Role) -> PathBuf {
    root.join(role.dir_name())
}

/// The certificate of `role` under `root`.
pub fn own_cert(root: &Path, role: Role) -> PathBuf {
    role_dir(root, role).join("own").join("cert.der")
}

/// Makes `role`'s certificate and key under `root` unless they exist;
/// `hosts` are the DNS names and addresses the certificate names (a client
/// checks the server's against the endpoint's host). Returns whether it
/// made them.
pub fn ensure(root: &Path, role: Role, hosts: &[String]) -> Result<bool, LinkError> {
    let dir = role_dir(root, role);
    let store = CertificateStore::new(&dir);
    store.ensure_pki_path().map_err(|e| pki_err(&dir, e))?;
    if store.own_certificate_path().exists() && store.own_private_key_path().exists() {
        return Ok(false);
    }
    let desc = ApplicationDescription {
        application_uri: role.application_uri().into(),
        application_name: role.application_name().into(),
        ..Default::default()
    };
    let mut names: Vec<String> = vec!["localhost".into(), "127.0.0.1".into()];
    names.extend(hosts.iter().cloned());
    names.extend(X509Data::computer_hostnames());
    names.sort();
    names.dedup();
    let mut data = X509Data::from((desc, Some(names)));
    data.key_size = 2048;
    data.certificate_duration_days = 3 * 365;
    data.organization = "autoshovel".into();
    store
        .create_and_store_application_instance_cert(&data, false)
        .map_err(|e| pki_err(&store.own_certificate_path(), e))?;
    let key = store.own_private_key_path();
    rewrap_pem(&key)?;
    owner_only(&key)?;
    Ok(true)
}

/// Rewrites a PEM file in the standard layout (RFC 7468: the label lines
/// on their own, base64 in lines of 64): async-opcua writes its key on one
/// line, which it reads back but OpenSSL (`openssl`, node, many PLC tools)
/// refuses.
fn rewrap_pem(path: &Path) -> Result<(), LinkError> {
    let text = fs::read_to_string(path).map_err(|e| pki_io(path, e))?;
    let malformed = || pki_err(path, "not a PEM file");
    let begin = text.find("-----BEGIN ").ok_or_else(malformed)?;
    let label_end = text[begin + 11..].find("-----").ok_or_else(malformed)? + begin + 11;
    let label = &text[begin + 11..label_end];
    let footer = format!("-----END {label}-----");
    let end = text.find(&footer).ok_or_else(malformed)?;
    let body: String = text[label_end + 5..end]
        .chars()
        .filter(|c| !c.is_whitespace())
        .collect();
    let mut out = format!("-----BEGIN {label}-----\n");
    for line in body.as_bytes().chunks(64) {
        out.push_str(std::str::from_utf8(line).map_err(|_| malformed())?);
        out.push('\n');
    }
    out.push_str(&footer);
    out.push('\n');
    fs::write(path, out).map_err(|e| pki_io(path, e))
}

/// Makes `key` readable and writable by its owner alone (0600), and its
/// folder enterable by the owner alone (0700): async-opcua writes keys
/// with the process's umask (0644 here).
fn owner_only(key: &Path) -> Result<(), LinkError> {
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        fs::set_permissions(key, fs::Permissions::from_mode(0o600)).map_err(|e| pki_io(key, e))?;
        if let Some(dir) = key.parent() {
            fs::set_permissions(dir, fs::Permissions::from_mode(0o700))
                .map_err(|e| pki_io(dir, e))?;
        }
    }
    #[cfg(not(unix))]
    let _ = key;
    Ok(())
}

/// Adds the certificate at `cert` (DER or PEM) to the trust list of the
/// application folder `dir`; returns where it went.
pub fn trust(dir: &Path, cert: &Path) -> Result<PathBuf, LinkError> {
    let bytes = fs::read(cert).map_err(|e| pki_io(cert, e))?;
    let x = X509::from_der(&bytes)
        .or_else(|_| X509::from_pem(&bytes))
        .map_err(|source| LinkError::Certificate {
            path: cert.to_path_buf(),
            what: "not an X.509 certificate (DER or PEM)",
            source,
        })?;
    let store = CertificateStore::new(dir);
    store.ensure_pki_path().map_err(|e| pki_err(dir, e))?;
    let to = store
        .trusted_certs_dir()
        .join(CertificateStore::cert_file_name(&x));
    let der = x.to_der().map_err(|source| LinkError::Certificate {
        path: cert.to_path_buf(),
        what: "could not be encoded as DER",
        source,
    })?;
    fs::write(&to, der).map_err(|e| pki_io(&to, e))?;
    // The store looks in rejected/ first: a certificate left there would
    // stay refused however trusted.
    let rejected = store
        .rejected_certs_dir()
        .join(CertificateStore::cert_file_name(&x));
    if let Err(e) = fs::remove_file(&rejected) {
        if e.kind() != std::io::ErrorKind::NotFound {
            return Err(pki_io(&rejected, e));
        }
    }
    Ok(to)
}

/// Checks a peer's certificate (DER, as the peer presented it) against
/// `role`'s trust list under `root`, by exact certificate: trust is pinned
/// to the certificates in `trusted/` (a CA there trusts nothing it signed;
/// issuer chains and revocation lists are not consulted, so a certificate
/// is revoked by taking it out of `trusted/`). An untrusted one is saved to
/// `rejected/`, and the error names it and the command that trusts it.
pub fn check_peer(root: &Path, role: Role, der: &[u8], endpoint: &str) -> Result<(), LinkError> {
    let dir = role_dir(root, role);
    let x = X509::from_der(der).map_err(|source| LinkError::Certificate {
        path: PathBuf::from(endpoint),
        what: "the peer's certificate is not X.509",
        source,
    })?;
    let store = CertificateStore::new(&dir);
    store.ensure_pki_path().map_err(|e| pki_err(&dir, e))?;
    let name = CertificateStore::cert_file_name(&x);
    let trusted = store.trusted_certs_dir().join(&name);
    if trusted.exists() && fs::read(&trusted).map_err(|e| pki_io(&trusted, e))? == der {
        return Ok(());
    }
    let rejected = store.rejected_certs_dir().join(&name);
    fs::write(&rejected, der).map_err(|e| pki_io(&rejected, e))?;
    Err(LinkError::Untrusted {
        endpoint: endpoint.to_string(),
        side: match role {
            Role::Workstation => "PLC",
            Role::Plc => "workstation",
        },
        certificate: format!(
            "{}, thumbprint {}",
            x.subject_name(),
            x.thumbprint().as_hex_string()
        ),
        saved: rejected.clone(),
        fix: format!(
            "check it, then: autoshovel pki trust --dir {} {}",
            dir.display(),
            rejected.display()
        ),
    })
}

/// What `init` did.
#[derive(Debug, Clone, Default)]
pub struct InitReport {
    /// Certificates made.
    pub made: Vec<PathBuf>,
    /// Certificates added to trust lists.
    pub trusted: Vec<PathBuf>,
    /// The password file, if it was made.
    pub password_file: Option<PathBuf>,
}

/// [`init`] when `root` does not exist at all (first use), else nothing.
pub fn init_if_absent(root: &Path) -> Result<Option<InitReport>, LinkError> {
    if root.exists() {
        return Ok(None);
    }
    init(root, &[]).map(Some)
}

/// Makes both applications' certificates under `root` (keeping any that
/// exist), has each trust the other, and makes the operator's password
/// file (mode 0600) unless it exists.
pub fn init(root: &Path, hosts: &[String]) -> Result<InitReport, LinkError> {
    let mut report = InitReport::default();
    for role in [Role::Plc, Role::Workstation] {
        if ensure(root, role, hosts)? {
            report.made.push(own_cert(root, role));
        }
    }
    for role in [Role::Plc, Role::Workstation] {
        let peer = own_cert(root, role.peer());
        report.trusted.push(trust(&role_dir(root, role), &peer)?);
    }
    let pw = root.join(PASSWORD_FILE);
    if !pw.exists() {
        let mut rng = rand::rngs::OsRng;
        const CHARS: &[u8] = b"abcdefghijkmnpqrstuvwxyzABCDEFGHJKLMNPQRSTUVWXYZ23456789";
        let secret: String = (0..24)
            .map(|_| CHARS[rng.gen_range(0..CHARS.len())] as char)
            .collect();
        write_secret(&pw, &secret)?;
        report.password_file = Some(pw);
    }
    Ok(report)
}

fn write_secret(path: &Path, secret: &str) -> Result<(), LinkError> {
    #[cfg(unix)]
    {
        use std::io::Write;
        use std::os::unix::fs::OpenOptionsExt;
        let mut f = fs::OpenOptions::new()
            .write(true)
            .create_new(true)
            .mode(0o600)
            .open(path)
            .map_err(|e| pki_io(path, e))?;
        f.write_all(secret.as_bytes()).map_err(|e| pki_io(path, e))
    }
    #[cfg(not(unix))]
    {
        fs::write(path, secret).map_err(|e| pki_io(path, e))
    }
}

/// Reads a password file (its first line).
pub fn read_password(path: &Path) -> Result<String, LinkError> {
    let s = fs::read_to_string(path).map_err(|e| {
        pki_err(
            path,
            format!("{e}; `autoshovel pki init` makes it, or pass --password-file"),
        )
    })?;
    let line = s.lines().next().unwrap_or("").trim().to_string();
    if line.is_empty() {
        return Err(pki_err(path, "the password file is empty"));
    }
    Ok(line)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keys_are_the_owners_alone_and_trust_takes_a_certificate_out_of_rejected() {
        let dir = tempfile::tempdir().unwrap();
        let root = dir.path().join("pki");
        // Each side makes its own key; neither trusts the other yet.
        ensure(&root, Role::Plc, &[]).unwrap();
        ensure(&root, Role::Workstation, &[]).unwrap();
        #[cfg(unix)]
        for role in [Role::Plc, Role::Workstation] {
            use std::os::unix::fs::PermissionsExt;
            let key = CertificateStore::new(&role_dir(&root, role)).own_private_key_path();
            let mode = fs::metadata(&key).unwrap().permissions().mode() & 0o777;
            assert_eq!(mode, 0o600, "{}", key.display());
        }
        // The key is standard PEM, lines of 64, as OpenSSL reads it.
        let key = CertificateStore::new(&role_dir(&root, Role::Plc)).own_private_key_path();
        let text = fs::read_to_string(&key).unwrap();
        assert!(text.starts_with("-----BEGIN PRIVATE KEY-----\n"), "{text}");
        assert!(text.lines().all(|l| l.len() <= 64), "{text}");
        // ... and async-opcua still reads it.
        let store = CertificateStore::new(&role_dir(&root, Role::Plc));
        assert!(store.read_own_pkey().is_ok());
        // The PLC's certificate as a refused connection leaves it.
        let plc_cert = own_cert(&root, Role::Plc);
        let x = X509::from_der(&fs::read(&plc_cert).unwrap()).unwrap();
        let ws = CertificateStore::new(&role_dir(&root, Role::Workstation));
        let rejected = ws
            .rejected_certs_dir()
            .join(CertificateStore::cert_file_name(&x));
        fs::copy(&plc_cert, &rejected).unwrap();
        let to = trust(&role_dir(&root, Role::Workstation), &plc_cert).unwrap();
        assert!(to.exists() && !rejected.exists());
        // Trusting again (nothing in rejected/) is no error.
        trust(&role_dir(&root, Role::Workstation), &plc_cert).unwrap();
    }
}
