"""Certificates for HTTPS on a robot's own network (`flask tls self-signed`).

HTTPS is what lets a browser on another machine use the Gamepad API and keeps passwords and
session cookies off the air. The command makes a small local CA and a server certificate it signs
(as mkcert does): trust ca.pem once on each operator's device, or accept the warning once per
browser. A team with its own CA uses its own certificate and key (ROVER_WEB_TLS_CERT, _KEY).

Run again (new host names, a certificate near its end), it keeps the CA and only issues a new
server certificate. A device that trusted ca.pem has also noted HSTS for the robot (browsers note
it only over a trusted connection), and under HSTS a certificate error cannot be clicked through:
a new CA would lock that tablet out of the GUI, the e-stop included, until HSTS expired. So the
CA's key is kept (ca-key.pem, 0600), and the CA is name-constrained to the hosts it was made for:
whoever steals the key can issue certificates for this robot's names only, not for any site a
trusting device visits. Hosts beyond those names need a new CA (`--new-ca`), to be trusted again.
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
CA_VALID_DAYS = 3650  # a CA's end locks trusting devices out as a new CA would: make it far off
CA_KEY = "ca-key.pem"


class NewCANeeded(ValueError):
    """The kept CA cannot sign for these hosts (outside its names, or no longer valid)."""


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


def _permitted(hosts: list[str]) -> list[x509.GeneralName]:
    names: list[x509.GeneralName] = []
    for host in hosts:
        try:
            names.append(x509.IPAddress(ipaddress.ip_network(ipaddress.ip_address(host))))
        except ValueError:
            names.append(x509.DNSName(host))
    return names


def _new_ca(hosts: list[str], now: datetime.datetime):
    ca_key = ec.generate_private_key(ec.SECP256R1())
    ca_name = _name(f"rover_web local CA {hosts[0]}")
    ca = (x509.CertificateBuilder()
          .subject_name(ca_name).issuer_name(ca_name)
          .public_key(ca_key.public_key())
          .serial_number(x509.random_serial_number())
          .not_valid_before(now - datetime.timedelta(minutes=5))
          .not_valid_after(now + datetime.timedelta(days=CA_VALID_DAYS))
          .add_extension(x509.BasicConstraints(ca=True, path_length=0), critical=True)
          .add_extension(x509.KeyUsage(digital_signature=False, content_commitment=False, key_encipherment=False,
                                       data_encipherment=False, key_agreement=False, key_cert_sign=True,
                                       crl_sign=True, encipher_only=False, decipher_only=False), critical=True)
          .add_extension(x509.NameConstraints(permitted_subtrees=_permitted(hosts), excluded_subtrees=None),
                         critical=True)
          .sign(ca_key, hashes.SHA256()))
    return ca, ca_key


def _kept_ca(directory: Path, hosts: list[str], now: datetime.datetime):
    """The CA an earlier run made, if it may sign for `hosts` until a new certificate's end; None
    when there is none; NewCANeeded when there is one that cannot."""
    ca_path, key_path = directory / "ca.pem", directory / CA_KEY
    if not ca_path.exists() and not key_path.exists():
        return None
    try:
        ca = x509.load_pem_x509_certificate(ca_path.read_bytes())
        ca_key = serialization.load_pem_private_key(key_path.read_bytes(), password=None)
    except (OSError, ValueError) as exc:
        raise NewCANeeded(f"the CA in {directory} cannot be read ({exc})") from None
    if ca.public_key().public_numbers() != ca_key.public_key().public_numbers():
        raise NewCANeeded(f"{CA_KEY} in {directory} is not the key of its ca.pem")
    if ca.not_valid_after_utc < now + datetime.timedelta(days=VALID_DAYS):
        raise NewCANeeded(f"the CA in {directory} ends on {ca.not_valid_after_utc:%Y-%m-%d}, before a new "
                          "certificate would")
    try:
        permitted = ca.extensions.get_extension_for_class(x509.NameConstraints).value.permitted_subtrees or []
    except x509.ExtensionNotFound:
        permitted = []
    outside = [h for h, name in zip(hosts, _permitted(hosts), strict=True) if name not in permitted]
    if outside:
        raise NewCANeeded(f"the CA in {directory} may only sign for the names it was made for, not "
                          f"{', '.join(outside)}")
    return ca, ca_key


def write_self_signed(directory: Path, hosts: list[str], new_ca: bool = False) -> tuple[Path, Path]:
    """Write cert.pem (the server's certificate for `hosts`) and key.pem (readable by its owner
    only), signed by the CA in ca.pem and ca-key.pem: the one an earlier run made, or with none
    there (or `new_ca`) a new one. NewCANeeded when the kept CA cannot sign for `hosts`.
    Returns the certificate's and the key's paths: the pair ROVER_WEB_TLS_CERT/KEY name."""
    if not hosts:
        raise ValueError("name at least one host")
    directory.mkdir(parents=True, exist_ok=True)
    now = datetime.datetime.now(datetime.UTC)
    valid = {"not_valid_before": now - datetime.timedelta(minutes=5),
             "not_valid_after": now + datetime.timedelta(days=VALID_DAYS)}
    kept = None if new_ca else _kept_ca(directory, hosts, now)
    ca, ca_key = kept or _new_ca(hosts, now)
    ca_name = ca.subject
    key = ec.generate_private_key(ec.SECP256R1())
    cert = (x509.CertificateBuilder()
            # No common name: browsers read only the SAN, and OpenSSL checks a CN that looks like a host
            # name (127.0.0.1 does) against the CA's DNS constraints, where an address is not listed.
            .subject_name(x509.Name([x509.NameAttribute(NameOID.ORGANIZATION_NAME, "rover_web (self-signed)")]))
            .issuer_name(ca_name)
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
    if kept is None:
        _replace(directory / CA_KEY, ca_key.private_bytes(serialization.Encoding.PEM,
                                                          serialization.PrivateFormat.PKCS8,
                                                          serialization.NoEncryption()), 0o600)
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
