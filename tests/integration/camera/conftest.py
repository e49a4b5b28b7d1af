"""Cameras in other processes and MJPEG clients, each closed after its test."""

import pytest

from tests.support.camera_peer import ImagePublisher
from tests.support.mjpeg import MjpegClient


@pytest.fixture
def image_publisher():
    made = []

    def make(topic, **kwargs):
        publisher = ImagePublisher(topic, **kwargs)
        made.append(publisher)
        return publisher

    yield make
    for publisher in made:
        publisher.close()


@pytest.fixture
def mjpeg_client():
    made = []

    def make(url, **kwargs):
        client = MjpegClient(url, **kwargs)
        made.append(client)
        return client

    yield make
    for client in made:
        client.close()
