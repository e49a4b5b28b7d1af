"""`flask tls self-signed`'s certificate: loads into an SSL context, names the hosts, key kept private."""

import datetime
import ipaddress
import ssl
import stat

import pytest
from cryptography import x509
from cryptography.hazmat.primitives import hashes, serialization
from cryptography.hazmat.primitives.asymmetric import ec

from rover_web.auth.tls import NewCANeeded, write_self_signed


def test_self_signed_certificate(tmp_path):
    cert_path, key_path = write_self_signed(tmp_path / "tls", ["robot.local", "127.0.0.1"])
    context = ssl.SSLContext(ssl.PROTOCOL_TLS_SERVER)
    context.load_cert_chain(cert_path, key_path)
    client = ssl.create_default_context(cafile=str(tmp_path / "tls" / "ca.pem"))  # trusting the local CA
    assert client.cert_store_stats()["x509_ca"] == 1
    cert = x509.load_pem_x509_certificate(cert_path.read_bytes())
    san = cert.extensions.get_extension_for_class(x509.SubjectAlternativeName).value
    assert san.get_values_for_type(x509.DNSName) == ["robot.local"]
    assert san.get_values_for_type(x509.IPAddress) == [ipaddress.ip_address("127.0.0.1")]
    assert stat.S_IMODE(key_path.stat().st_mode) == 0o600


def test_rewriting_the_key_replaces_a_planted_symlink_and_never_writes_through_it(tmp_path):
    directory = tmp_path / "tls"
    directory.mkdir()
    elsewhere = tmp_path / "elsewhere.pem"
    elsewhere.write_text("not yours")
    (directory / "key.pem").symlink_to(elsewhere)
    _, key_path = write_self_signed(directory, ["localhost"])
    assert elsewhere.read_text() == "not yours"
    assert not key_path.is_symlink() and b"PRIVATE KEY" in key_path.read_bytes()
    assert stat.S_IMODE(key_path.stat().st_mode) == 0o600


def test_rewriting_a_loose_key_leaves_a_0600_file_and_no_temporary_files(tmp_path):
    directory = tmp_path / "tls"
    write_self_signed(directory, ["localhost"])
    (directory / "key.pem").chmod(0o644)
    first = (directory / "key.pem").read_bytes()
    write_self_signed(directory, ["localhost"])
    assert (directory / "key.pem").read_bytes() != first
    assert stat.S_IMODE((directory / "key.pem").stat().st_mode) == 0o600
    assert sorted(p.name for p in directory.iterdir()) == ["ca-key.pem", "ca.pem", "cert.pem", "key.pem"]


def handshake(cert_path, key_path, ca_path, host: str) -> None:
    """A real TLS handshake in memory, the client trusting only `ca_path`; ssl.SSLError if refused."""
    server_ctx = ssl.SSLContext(ssl.PROTOCOL_TLS_SERVER)
    server_ctx.load_cert_chain(cert_path, key_path)
    client_ctx = ssl.create_default_context(cafile=str(ca_path))
    c_in, c_out, s_in, s_out = ssl.MemoryBIO(), ssl.MemoryBIO(), ssl.MemoryBIO(), ssl.MemoryBIO()
    client = client_ctx.wrap_bio(c_in, c_out, server_hostname=host)
    server = server_ctx.wrap_bio(s_in, s_out, server_side=True)
    done = set()
    for _ in range(10):
        for name, end, out, into in (("client", client, c_out, s_in), ("server", server, s_out, c_in)):
            if name not in done:
                try:
                    end.do_handshake()
                    done.add(name)
                except ssl.SSLWantReadError:
                    pass
            into.write(out.read())
        if done == {"client", "server"}:
            return
    raise AssertionError("the handshake did not finish")


def test_running_again_keeps_the_ca_a_device_trusts(tmp_path):
    """A device that trusted ca.pem has noted HSTS: a new CA would leave it a certificate error it
    may not click through, e-stop included. The second run signs with the first run's CA."""
    directory = tmp_path / "tls"
    write_self_signed(directory, ["robot.local", "127.0.0.1"])
    trusted = tmp_path / "trusted-ca.pem"  # what the tablet installed
    trusted.write_bytes((directory / "ca.pem").read_bytes())
    cert_path, key_path = write_self_signed(directory, ["127.0.0.1"])
    assert (directory / "ca.pem").read_bytes() == trusted.read_bytes()
    handshake(cert_path, key_path, trusted, "127.0.0.1")
    assert stat.S_IMODE((directory / "ca-key.pem").stat().st_mode) == 0o600


def test_the_kept_ca_signs_only_for_its_own_names(tmp_path):
    directory = tmp_path / "tls"
    write_self_signed(directory, ["robot.local", "127.0.0.1"])
    before = {p.name: p.read_bytes() for p in directory.iterdir()}
    with pytest.raises(NewCANeeded, match="elsewhere.example"):
        write_self_signed(directory, ["robot.local", "elsewhere.example"])
    assert {p.name: p.read_bytes() for p in directory.iterdir()} == before  # nothing written
    # A stolen ca-key.pem cannot vouch for another site to a device that trusts ca.pem.
    ca = x509.load_pem_x509_certificate((directory / "ca.pem").read_bytes())
    ca_key = serialization.load_pem_private_key((directory / "ca-key.pem").read_bytes(), password=None)
    forged_key = ec.generate_private_key(ec.SECP256R1())
    now = datetime.datetime.now(datetime.UTC)
    forged = (x509.CertificateBuilder().subject_name(x509.Name([])).issuer_name(ca.subject)
              .public_key(forged_key.public_key()).serial_number(x509.random_serial_number())
              .not_valid_before(now - datetime.timedelta(minutes=5)).not_valid_after(now + datetime.timedelta(days=1))
              .add_extension(x509.SubjectAlternativeName([x509.DNSName("bank.example")]), critical=True)
              .sign(ca_key, hashes.SHA256()))
    (tmp_path / "forged.pem").write_bytes(forged.public_bytes(serialization.Encoding.PEM))
    (tmp_path / "forged-key.pem").write_bytes(forged_key.private_bytes(
        serialization.Encoding.PEM, serialization.PrivateFormat.PKCS8, serialization.NoEncryption()))
    with pytest.raises(ssl.SSLCertVerificationError):
        handshake(tmp_path / "forged.pem", tmp_path / "forged-key.pem", directory / "ca.pem", "bank.example")
    # Asked for, a new CA is made, and it is what devices must trust from then on.
    cert_path, key_path = write_self_signed(directory, ["robot.local", "elsewhere.example"], new_ca=True)
    assert (directory / "ca.pem").read_bytes() != before["ca.pem"]
    handshake(cert_path, key_path, directory / "ca.pem", "elsewhere.example")
