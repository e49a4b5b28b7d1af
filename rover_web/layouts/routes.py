"""The layouts API. Reading and picking: any signed-in user (PUT /api/me/layout is listed in
auth/policy.py); creating, replacing and deleting: operators and admins (the default for writes)."""

from __future__ import annotations

from flask import Blueprint, jsonify, request

from rover_web.auth import signed_in_name
from rover_web.core.state import current_feature
from rover_web.web.api_messages import text_of
from rover_web.web.http import ApiError, error_response, json_body
from rover_web.web.validate import InvalidInput, only_keys

from .schema import InvalidLayout, validate
from .service import LayoutService
from .store import NameTaken

bp = Blueprint("layouts", __name__)


def _service() -> LayoutService:
    return current_feature(LayoutService)


def _by() -> str:
    return signed_in_name() or request.remote_addr or "unknown"  # with sign-in off, the address


def _found(layout_id: int) -> dict:
    doc = _service().store.get(layout_id)
    if doc is None:
        raise ApiError(404, "not_found", "no layout %(layout_id)s on this robot; GET /api/layouts lists them",
                       layout_id=layout_id)
    return doc


@bp.get("/api/layouts")
def list_layouts():
    service = _service()
    active_id, _doc = service.active()
    return jsonify(layouts=service.store.list(), active=active_id, kind=service.store.kind)


@bp.post("/api/layouts")
def add_layout():
    doc = validate(json_body())
    layout_id = _service().store.add(doc, _by())
    return jsonify(id=layout_id, layout=doc), 201


@bp.get("/api/layouts/<int:layout_id>")
def get_layout(layout_id: int):
    """The layout as it is imported (POST /api/layouts takes this file back): export."""
    response = jsonify(_found(layout_id))
    if request.args.get("download"):
        response.headers["Content-Disposition"] = f'attachment; filename="layout-{layout_id}.json"'
    return response


@bp.put("/api/layouts/<int:layout_id>")
def replace_layout(layout_id: int):
    doc = validate(json_body())
    if not _service().store.replace(layout_id, doc, _by()):
        _found(layout_id)
    return jsonify(id=layout_id, layout=doc)


@bp.delete("/api/layouts/<int:layout_id>")
def delete_layout(layout_id: int):
    if not _service().store.delete(layout_id):
        _found(layout_id)
    return jsonify(deleted=layout_id)


@bp.get("/api/me/layout")
def my_layout():
    active_id, doc = _service().active()
    return jsonify(id=active_id, layout=doc, user=signed_in_name())


@bp.put("/api/me/layout")
def choose_layout():
    body = json_body()
    only_keys(body, {"id"})
    layout_id = body.get("id")
    if isinstance(layout_id, bool) or not isinstance(layout_id, int):
        raise ApiError(400, "bad_type" if "id" in body else "missing_field", "'id' must be a layout's id (an integer)")
    service = _service()
    if not service.store.choose(service.user_key(), layout_id):
        raise ApiError(404, "not_found", "no layout %(layout_id)s on this robot; GET /api/layouts lists them",
                       layout_id=layout_id)
    return jsonify(id=layout_id, user=signed_in_name())


@bp.errorhandler(InvalidLayout)
def _invalid(exc: InvalidLayout):
    response = jsonify(error=exc.code, message=str(exc), field=exc.field)
    response.status_code = 400
    return response


@bp.errorhandler(InvalidInput)
def _invalid_input(exc: InvalidInput):
    return error_response(400, exc.code, text_of(exc))


@bp.errorhandler(NameTaken)
def _name_taken(exc: NameTaken):
    return error_response(409, "name_taken", "a layout named %(name)s exists on this robot; choose another name or "
                                             "PUT that layout", name=repr(str(exc)))
