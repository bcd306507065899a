"""Robot API ports: with the robots' addresses known, a port accepts only its own robot."""

from __future__ import annotations

from contracts.match_spec import MatchSpec
from simulator.api.endpoints import endpoints_from_spec


def _spec(red_addresses: list[str], blue_addresses: list[str]) -> MatchSpec:
    def team(color: str, base: int, addresses: list[str]) -> dict[str, object]:
        pose = {"x_m": -1.0, "y_m": 0.0, "yaw_rad": 0.0}
        return {
            "color": color, "team_id": 1 if color == "red" else 2, "name": color,
            "hosts": ["127.0.0.1", *addresses], "robot_addresses": addresses,
            "players": [
                {"number": n, "model": "kid-default", "port": base + n, "half_time_pose": pose,
                 "reentry_pose": pose, "shootout_pose": pose, "goalkeeper_pose": pose}
                for n in (1, 2)
            ],
        }

    return MatchSpec.from_dict({
        "match_id": "m", "seed": 1, "game_type": "NORMAL", "field_class": "kid",
        "side_left": "red", "kickoff": "red",
        "red": team("red", 10000, red_addresses), "blue": team("blue", 10020, blue_addresses),
    })


def test_a_port_refuses_the_other_robots_addresses() -> None:
    spec = _spec(["10.0.1.11", "10.0.1.12"], ["10.0.2.11", "10.0.2.12"])
    by_key = {e.key: e for e in endpoints_from_spec(spec)}
    red1 = by_key["red-1"]
    assert red1.allowed_ips == {"127.0.0.1", "10.0.1.11"}
    assert red1.others["10.0.1.12"] == "red-2" and red1.others["10.0.2.11"] == "blue-1"
    assert by_key["blue-2"].allowed_ips == {"127.0.0.1", "10.0.2.12"}


def test_without_addresses_the_team_hosts_are_allowed() -> None:
    spec = _spec([], [])
    for endpoint in endpoints_from_spec(spec):
        assert endpoint.allowed_ips == {"127.0.0.1"} and not endpoint.others


def test_robots_sharing_one_address_may_each_use_it() -> None:
    spec = _spec(["127.0.0.1", "127.0.0.1"], ["127.0.0.1", "127.0.0.1"])
    for endpoint in endpoints_from_spec(spec):
        assert endpoint.allowed_ips == {"127.0.0.1"} and not endpoint.others
