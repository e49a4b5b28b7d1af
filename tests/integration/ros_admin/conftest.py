import pytest

from tests.support.action_peer import AdminPeer
from tests.support.waiting import wait_until

PEER = "/peer_ns/param_peer"
PEER_URL = "/api/nodes/peer_ns/param_peer"


@pytest.fixture
def admin_peer():
    peer = AdminPeer()
    yield peer
    peer.close()


@pytest.fixture
def action_peer(action_server):
    """The root conftest's action_server, serving /fibonacci unless told otherwise."""
    return lambda name="/fibonacci": action_server(name)


def wait_for_parameters(client, timeout: float = 15.0) -> dict:
    """The peer's parameters once the app's node has discovered it and its services."""
    def listed():
        response = client.get(PEER_URL + "/parameters")
        return response.status_code == 200 and {p["name"]: p for p in response.get_json()["parameters"]}
    return wait_until(listed, timeout, "the peer's parameters")


def wait_for_service(client, name: str, timeout: float = 15.0) -> None:
    wait_until(lambda: any(s["name"] == name for s in client.get("/api/services").get_json()["services"]),
               timeout, f"service {name}")
