"""The revocation registry (rover_web/auth/revocation.py), with a stand-in for the database's verdicts."""

from rover_web.auth.revocation import Credential, Revocations

ADA = Credential("ada", "operator", "e1", "token", "7")
BOB = Credential("bob", "viewer", "e2", "session", "abc")


def registry(verdicts: dict):
    asked = []

    def ended(credential):
        asked.append(credential)
        return verdicts.get(credential)

    return Revocations(ended), asked


def test_only_the_streams_of_an_ended_credential_close_once_with_the_reason():
    verdicts = {}
    revocations, asked = registry(verdicts)
    closed = []
    revocations.register(ADA, lambda reason: closed.append(("ada 1", reason)))
    revocations.register(ADA, lambda reason: closed.append(("ada 2", reason)))
    revocations.register(BOB, lambda reason: closed.append(("bob", reason)))
    assert revocations.check() == 0 and closed == []
    verdicts[ADA] = "token revoked"
    asked.clear()
    assert revocations.check() == 2
    assert sorted(closed) == [("ada 1", "token revoked"), ("ada 2", "token revoked")]
    assert asked.count(ADA) == 1  # one question per credential, however many streams it has
    assert revocations.check() == 0 and len(closed) == 2  # never twice
    assert revocations.count == 1


def test_a_cancelled_registration_is_not_closed_and_the_gate_follows_what_is_open():
    revocations, _ = registry({ADA: "user removed"})
    assert not revocations.any_open.is_set()
    closed = []
    with revocations.register(ADA, closed.append):
        assert revocations.any_open.is_set()
    assert not revocations.any_open.is_set()
    assert revocations.check() == 0 and closed == []


def test_a_failing_close_does_not_keep_the_others_open(caplog):
    revocations, _ = registry({ADA: "signed out"})
    closed = []

    def broken(_reason):
        raise RuntimeError("boom")

    revocations.register(ADA, broken)
    revocations.register(ADA, closed.append)
    assert revocations.check() == 2
    assert closed == ["signed out"]
    assert "boom" in caplog.text
