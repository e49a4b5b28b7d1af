"""`flask tls self-signed`'s certificate: loads into an SSL context, names the hosts, key kept private."""

import ipaddress
import ssl
import stat

from cryptography import x509

from rover_web.auth.tls import write_self_signed


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
    assert sorted(p.name for p in directory.iterdir()) == ["ca.pem", "cert.pem", "key.pem"]
