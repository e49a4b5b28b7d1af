"""Certificates for HTTPS on a robot's own network (`flask tls self-signed`).

HTTPS is what lets a browser on another machine use the Gamepad API and keeps passwords and
session cookies off the air. The command makes a small local CA and a server certificate it signs
(as mkcert does): trust ca.pem once on each operator's device, or accept the warning once per
browser. A team with its own CA uses its own certificate and key (ROVER_WEB_TLS_CERT, _KEY).
"""

from __future__ import annotations

import contextlib
import datetime
import ipaddress
import os
import socket
import tempfile
from pathlib import Path

from cryptography import x509
from cryptography.hazmat.primitives import hashes, serialization
from cryptography.hazmat.primitives.asymmetric import ec
from cryptography.x509.oid import ExtendedKeyUsageOID, NameOID

VALID_DAYS = 825  # the longest validity browsers accept for a server certificate


def default_hosts() -> list[str]:
    return sorted({"localhost", "127.0.0.1", "::1", socket.gethostname()})


def _san(hosts: list[str]) -> x509.SubjectAlternativeName:
    names: list[x509.GeneralName] = []
    for host in hosts:
        try:
            names.append(x509.IPAddress(ipaddress.ip_address(host)))
        except ValueError:
            names.append(x509.DNSName(host))
    return x509.SubjectAlternativeName(names)


def _name(common_name: str) -> x509.Name:
    return x509.Name([x509.NameAttribute(NameOID.COMMON_NAME, common_name[:64]),
                      x509.NameAttribute(NameOID.ORGANIZATION_NAME, "rover_web (self-signed)")])


def write_self_signed(directory: Path, hosts: list[str]) -> tuple[Path, Path]:
    """Write ca.pem (a local CA to trust on each operator's device), cert.pem (the server's
    certificate for `hosts`, signed by that CA) and key.pem (readable by its owner only).
    Returns the certificate's and the key's paths: the pair ROVER_WEB_TLS_CERT/KEY name."""
    if not hosts:
        raise ValueError("name at least one host")
    directory.mkdir(parents=True, exist_ok=True)
    now = datetime.datetime.now(datetime.UTC)
    valid = {"not_valid_before": now - datetime.timedelta(minutes=5),
             "not_valid_after": now + datetime.timedelta(days=VALID_DAYS)}
    # The CA's key signs once, here, and is not kept: nothing else can be issued in its name.
    ca_key = ec.generate_private_key(ec.SECP256R1())
    ca_name = _name(f"rover_web local CA {hosts[0]}")
    ca = (x509.CertificateBuilder()
          .subject_name(ca_name).issuer_name(ca_name)
          .public_key(ca_key.public_key())
          .serial_number(x509.random_serial_number())
          .not_valid_before(valid["not_valid_before"]).not_valid_after(valid["not_valid_after"])
          .add_extension(x509.BasicConstraints(ca=True, path_length=0), critical=True)
          .add_extension(x509.KeyUsage(digital_signature=False, content_commitment=False, key_encipherment=False,
                                       data_encipherment=False, key_agreement=False, key_cert_sign=True,
                                       crl_sign=True, encipher_only=False, decipher_only=False), critical=True)
          .sign(ca_key, hashes.SHA256()))
    key = ec.generate_private_key(ec.SECP256R1())
    cert = (x509.CertificateBuilder()
            .subject_name(_name(hosts[0])).issuer_name(ca_name)
            .public_key(key.public_key())
            .serial_number(x509.random_serial_number())
            .not_valid_before(valid["not_valid_before"]).not_valid_after(valid["not_valid_after"])
            .add_extension(_san(hosts), critical=False)
            .add_extension(x509.BasicConstraints(ca=False, path_length=None), critical=True)
            .add_extension(x509.ExtendedKeyUsage([ExtendedKeyUsageOID.SERVER_AUTH]), critical=False)
            .sign(ca_key, hashes.SHA256()))
    ca_path, cert_path, key_path = directory / "ca.pem", directory / "cert.pem", directory / "key.pem"
    key_bytes = key.private_bytes(serialization.Encoding.PEM, serialization.PrivateFormat.PKCS8,
                                  serialization.NoEncryption())
    _replace(key_path, key_bytes, 0o600)
    _replace(ca_path, ca.public_bytes(serialization.Encoding.PEM), 0o644)
    _replace(cert_path, cert.public_bytes(serialization.Encoding.PEM), 0o644)
    return cert_path, key_path


def _replace(path: Path, data: bytes, mode: int) -> None:
    """Write a new file beside `path` (mkstemp: 0600 from the first byte, then `mode`) and rename it
    over `path`. Opening `path` itself would follow a symlink planted there (and write the key
    wherever it points) and keep an old file's looser mode until a chmod; a rename replaces the
    name, never what it pointed to, and the key is never readable by others for an instant."""
    fd, temp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    try:
        with os.fdopen(fd, "wb") as f:
            f.write(data)
            f.flush()
            os.fsync(f.fileno())
        os.chmod(temp, mode)
        os.replace(temp, path)
    except BaseException:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(temp)
        raise
