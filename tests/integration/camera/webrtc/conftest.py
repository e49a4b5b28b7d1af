"""Fixtures for WHEP tests: a live server whose host candidates are 127.0.0.1 only, cameras, clients."""

import pytest

from tests.conftest import closing_factory

LOOPBACK_ONLY = {"ROVER_WEB_WEBRTC_HOST_ADDRESSES": ["127.0.0.1"]}


@pytest.fixture
def webrtc_server(live_server_factory):
    def make(**settings):
        return live_server_factory(**{**LOOPBACK_ONLY, **settings})
    return make


@pytest.fixture
def camera():
    """make(topic, width=, height=, hz=): tests/support/peers/image_publisher.py in its own process."""
    from tests.support.camera_peer import ImagePublisher

    yield from closing_factory(ImagePublisher)


@pytest.fixture
def whep():
    """make(base_url, query, teleop=False, headers=None): a WhepClient, closed after the test."""
    from tests.support.whep import WhepClient

    yield from closing_factory(WhepClient)
