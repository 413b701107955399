// PEM for node's OpenSSL from the PKI that autoshovel makes: certificates
// are DER there, and keys made before autoshovel rewrapped them sit on one
// line, which OpenSSL refuses. Shared by client.js, plc.js, bystander.js.
"use strict";
const fs = require("fs");
const path = require("path");

function pemLines(label, b64) {
  return `-----BEGIN ${label}-----\n${b64.match(/.{1,64}/g).join("\n")}\n-----END ${label}-----\n`;
}

// Writes ROLE's certificate and key (pki/ROLE) as standard PEM into
// SCRATCH; returns { cert, key } paths.
function ownPem(pki, role, scratch) {
  const cert = path.join(scratch, `${role}.pem`);
  const der = fs.readFileSync(path.join(pki, role, "own", "cert.der"));
  fs.writeFileSync(cert, pemLines("CERTIFICATE", der.toString("base64")));
  const text = fs.readFileSync(path.join(pki, role, "private", "private.pem"), "utf8");
  const m = text.match(/-----BEGIN ([A-Z ]+)-----([\s\S]*?)-----END \1-----/);
  const key = path.join(scratch, `${role}.key`);
  fs.writeFileSync(key, pemLines(m[1], m[2].replace(/\s+/g, "")), { mode: 0o600 });
  return { cert, key };
}

module.exports = { ownPem };
