"""``/docs`` of ``hlvs serve``: the interactive API document (Swagger UI) from the package's own
copy of Swagger UI (``static/swagger``, copied from the ``swagger-ui-dist`` npm package by
``web/build.mjs``), so that it works on a machine without the internet. FastAPI's own pages load
Swagger UI and ReDoc from a CDN and are blank offline: they are replaced (``/docs``) and removed
(``/redoc``). Mounted by ``hlvs.app`` after :mod:`viewer.service_pages`, which serves
``/watch/static``.
"""

from __future__ import annotations

from fastapi import FastAPI
from fastapi.openapi.docs import get_swagger_ui_html
from fastapi.responses import HTMLResponse
from starlette.routing import Route

ASSETS = "/watch/static/swagger"


def docs_page(*, title: str, openapi_url: str) -> HTMLResponse:
    return get_swagger_ui_html(
        openapi_url=openapi_url, title=f"{title}: API",
        swagger_js_url=f"{ASSETS}/swagger-ui-bundle.js",
        swagger_css_url=f"{ASSETS}/swagger-ui.css",
        swagger_favicon_url=f"{ASSETS}/favicon-32x32.png",
        swagger_ui_parameters={"persistAuthorization": False},
    )


def mount(app: FastAPI) -> None:
    docs_url, openapi_url = app.docs_url or "/docs", app.openapi_url or "/openapi.json"
    gone = {docs_url, app.redoc_url}
    app.router.routes[:] = [r for r in app.router.routes
                            if not (isinstance(r, Route) and r.path in gone)]
    title = app.title

    @app.get(docs_url, include_in_schema=False)
    def docs() -> HTMLResponse:
        return docs_page(title=title, openapi_url=openapi_url)


__all__ = ["ASSETS", "docs_page", "mount"]
