"""Python client of the HTTP environment API (:mod:`service.routers.envs`), like gym-http-api's.

    client = EnvClient("http://127.0.0.1:8000", token="hlvs_...")
    instance = client.env_create("hlvs/Kick-v0", perception=True)
    obs = client.env_reset(instance, seed=1)
    obs, reward, done, info = client.env_step(instance, [0.0] * 20)
    client.env_monitor_start(instance, "monitor", video_callable=True)  # gym-http-api's form
    ...
    client.env_monitor_close(instance)  # the files are now in ./monitor as well
    client.download(instance, "episodes.jsonl", "episodes.jsonl")
    client.env_close(instance)

Errors come back as :class:`EnvApiError` with the HTTP status, the service's error kind and its
message.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, TypedDict

import httpx

from contracts import JSONObject
from envs.errors import EnvError


class EnvApiError(EnvError):
    def __init__(self, *, status: int, kind: str, message: str, url: str) -> None:
        self.status = status
        self.kind = kind
        self.message = message
        self.url = url
        super().__init__(f"{url}: HTTP {status} {kind}: {message}")


class MonitorFileRecord(TypedDict):
    """A file the service's monitor of an instance wrote."""

    name: str
    bytes: int


class EnvClient:
    """The service's environment API (gym-http-api's calls). Observations, infos and spaces
    come as the service answers them: free JSON."""

    def __init__(self, base_url: str, *, token: str | None, timeout_s: float = 60.0) -> None:
        headers = {"Authorization": f"Bearer {token}"} if token else {}
        self._http = httpx.Client(base_url=base_url.rstrip("/"), headers=headers,
                                  timeout=timeout_s)  # fmt: skip
        self._directories: dict[str, Path] = {}  # instance -> env_monitor_start's directory

    def _call(self, method: str, path: str, body: JSONObject | None = None) -> Any:
        try:
            response = self._http.request(method, path, json=body)
        except httpx.HTTPError as exc:
            raise EnvApiError(status=0, kind="unreachable", message=str(exc), url=path) from exc
        if response.status_code >= 400:
            try:
                data = response.json()
            except ValueError:
                data = {"error": "http_error", "message": response.text[:200]}
            raise EnvApiError(
                status=response.status_code, kind=str(data.get("error")),
                message=str(data.get("message")), url=path,
            )  # fmt: skip
        return response.json()

    def env_create(self, env_id: str, **kwargs: Any) -> str:
        return str(
            self._call("POST", "/v1/envs/", {"env_id": env_id, "kwargs": kwargs})["instance_id"]
        )

    def env_list_all(self) -> dict[str, str]:
        return dict(self._call("GET", "/v1/envs/")["all_envs"])

    def env_reset(self, instance_id: str, seed: int | None = None) -> JSONObject:
        return dict(
            self._call("POST", f"/v1/envs/{instance_id}/reset/", {"seed": seed})["observation"]
        )

    def env_step(
        self, instance_id: str, action: list[float]
    ) -> tuple[JSONObject, float, bool, JSONObject]:
        data = self._call("POST", f"/v1/envs/{instance_id}/step/", {"action": list(action)})
        return data["observation"], float(data["reward"]), bool(data["done"]), data["info"]

    def env_action_space_info(self, instance_id: str) -> JSONObject:
        return dict(self._call("GET", f"/v1/envs/{instance_id}/action_space/")["info"])

    def env_monitor_start(
        self, instance_id: str, directory: str | Path | None = None, force: bool = False,
        resume: bool = False, video_callable: bool = False, *, video: bool | None = None,
    ) -> None:
        """Start recording episodes; gym-http-api's signature (``directory``, ``force``,
        ``resume``, ``video_callable``), so ported code runs unchanged.

        The monitor's files stay with the service (:meth:`monitor_files`, :meth:`download`);
        with ``directory``, :meth:`env_monitor_close` also downloads them into that folder on
        this machine. ``video`` (or a true ``video_callable``) records a video too."""
        record_video = bool(video_callable) if video is None else video
        body: JSONObject = {"force": force, "resume": resume, "video": record_video}
        self._call("POST", f"/v1/envs/{instance_id}/monitor/start/", body)
        if directory is None:
            self._directories.pop(instance_id, None)
        else:
            self._directories[instance_id] = Path(directory)

    def env_monitor_close(self, instance_id: str) -> JSONObject:
        stats = dict(self._call("POST", f"/v1/envs/{instance_id}/monitor/close/")["stats"])
        directory = self._directories.pop(instance_id, None)
        if directory is not None:
            directory.mkdir(parents=True, exist_ok=True)
            for entry in self.monitor_files(instance_id):
                self.download(instance_id, str(entry["name"]), directory / str(entry["name"]))
        return stats

    def monitor_files(self, instance_id: str) -> list[MonitorFileRecord]:
        return list(self._call("GET", f"/v1/envs/{instance_id}/monitor/files/")["files"])

    def download(self, instance_id: str, name: str, destination: str | Path) -> Path:
        path = f"/v1/envs/{instance_id}/monitor/files/{name}"
        response = self._http.get(path)
        if response.status_code >= 400:
            data = response.json()
            raise EnvApiError(status=response.status_code, kind=str(data.get("error")),
                              message=str(data.get("message")), url=path)  # fmt: skip
        out = Path(destination)
        out.write_bytes(response.content)
        return out

    def env_close(self, instance_id: str) -> None:
        self._call("POST", f"/v1/envs/{instance_id}/close/")

    def close(self) -> None:
        self._http.close()

    def __enter__(self) -> EnvClient:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
