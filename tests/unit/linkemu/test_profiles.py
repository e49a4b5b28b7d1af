"""The named profiles, custom ones from flags, and addresses."""

import pytest

from rover_web.linkemu import PROFILES, parse_address, profile


def test_the_issues_profiles_have_its_figures():
    assert (PROFILES["wifi-good"].rate_kbps, PROFILES["wifi-good"].delay_ms, PROFILES["wifi-good"].jitter_ms) \
        == (20_000, 10, 5)
    edge = PROFILES["wifi-edge"]
    assert (edge.rate_kbps, edge.delay_ms, edge.jitter_ms, edge.stall_ms, edge.stall_every_s) == (2000, 60, 40, 400, 10)
    radio = PROFILES["radio"]
    assert (radio.rate_kbps, radio.delay_ms, radio.jitter_ms, radio.outage_s, radio.outage_every_s) \
        == (500, 150, 50, 3, 60)
    assert radio.stall_ms > 0
    star = PROFILES["starlink"]
    assert (star.rate_kbps, star.delay_ms, star.jitter_ms, star.loss) == (15_000, 30, 10, 0.02)


def test_custom_takes_its_values_from_flags_and_a_profile_can_be_overridden():
    p = profile("custom", rate_kbps=300, delay_ms=200, loss=0.05, buffer_kb=None)
    assert (p.name, p.rate_kbps, p.delay_ms, p.loss, p.buffer_kb) == ("custom", 300, 200, 0.05, 256)
    assert profile("wifi-edge", buffer_kb=32).buffer_kb == 32
    assert profile("wifi-edge").rtt_ms == 120
    assert "2 Mbit/s" in profile("wifi-edge").describe()


@pytest.mark.parametrize("bad", [{"rate_kbps": 0}, {"loss": 1.0}, {"delay_ms": -1}, {"buffer_kb": 0},
                                 {"outage_every_s": 5, "outage_s": 5}])
def test_impossible_values_are_refused(bad):
    with pytest.raises(ValueError):
        profile("custom", **bad)


def test_an_unknown_profile_names_the_known_ones():
    with pytest.raises(ValueError, match="wifi-good"):
        profile("dialup")


def test_addresses():
    assert parse_address("127.0.0.1:8000") == ("127.0.0.1", 8000)
    assert parse_address("[::1]:80") == ("::1", 80)
    for bad in ("8000", "127.0.0.1:", "host:port", ":80", "1.2.3.4:70000"):
        with pytest.raises(ValueError):
            parse_address(bad)
