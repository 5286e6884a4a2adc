"""A --ray-address where nothing answers is refused at once, with the reason."""

from __future__ import annotations

import socket

import pytest

from explaindrive.agent.ray_pool import unreachable_ray_address


def closed_port() -> int:
    with socket.socket() as s:  # bound, never listening: connections are refused
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def test_a_listening_address_passes() -> None:
    with socket.socket() as server:
        server.bind(("127.0.0.1", 0))
        server.listen()
        port = server.getsockname()[1]
        assert unreachable_ray_address(f"127.0.0.1:{port}") is None
        assert unreachable_ray_address(f"ray://127.0.0.1:{port}") is None
    assert unreachable_ray_address("auto") is None  # left to Ray


def test_a_refused_connection_is_named() -> None:
    port = closed_port()
    assert unreachable_ray_address(f"127.0.0.1:{port}") == (
        f"no Ray cluster answers at --ray-address 127.0.0.1:{port} (Connection refused)"
    )


@pytest.mark.parametrize("address", ["nonsense", "host:", ":6379", "host:0", "host:70000"])
def test_an_address_that_is_not_host_port(address: str) -> None:
    assert unreachable_ray_address(address) == (
        f"--ray-address {address!r} is not host:port (e.g. 10.0.0.5:6379)"
    )
