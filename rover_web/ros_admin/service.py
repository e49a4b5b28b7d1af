"""RosAdmin: the per-app object behind /api/nodes, /api/services, /api/actions and the /ros page.

Every call goes through rover_web.ros.admin.AdminNode (its own node and executor thread) and waits
with a timeout; every set, call, goal and cancel is written to the operator log with its
arguments and outcome (the panels' log, under the name "ros"), secrets left out.

Before anything is sent: the allow and deny rules (access.py), the e-stop (service calls and goals
always, parameter sets on ROVER_WEB_ROS_ADMIN_SAFETY_NODES), and no known navigation goal
(navigation.py). Who may ask at all is the auth policy's (admin for writes) and the mode's
(ROVER_WEB_ROS_ADMIN: on, read-only, off; routes.py).
"""

from __future__ import annotations

import logging
import threading
from typing import Any

from rover_web.core.state import Rover
from rover_web.estop import EStopEngaged
from rover_web.panels.oplog import OperatorLog
from rover_web.ros.admin import AdminNode, NoAnswer
from rover_web.ros.fields import FieldError, build, describe
from rover_web.ros.typesupport import UnknownMessageType, interface_class, is_interface_package
from rover_web.web.api_messages import explain, text_of

from .access import AccessRules, matches_any, parameter_subjects, parse_rules
from .goals import Goal, GoalBook
from .navigation import navigation_refusal
from .parameters import ParameterRefused, check_value
from .secret_params import HIDDEN, is_secret, scrub

log = logging.getLogger(__name__)

LOG_NAME = "ros"  # the operator log's `panel` column for everything this feature does
LOG_KEEP = 500
PARAMETER_TIMEOUT_S = 3.0
GOAL_TIMEOUT_S = 5.0
CANCEL_TIMEOUT_S = 3.0
# Services whose answers are parameter values: their responses are not logged (secrets).
VALUE_SERVICES = ("/get_parameters",)
MODES = ("on", "read-only", "off")


class AdminRefused(Exception):
    """A request this feature refuses; `status` and `code` become the HTTP answer."""

    def __init__(self, status: int, code: str, message: str):
        super().__init__(message)
        self.status, self.code = status, code


def _type_class(type_name: str, kind: str) -> type:
    if not isinstance(type_name, str) or f"/{kind}/" not in type_name:
        raise AdminRefused(400, "bad_type_name", explain("'type' must name a %(kind)s type like %(example)s", kind=kind,
                           example="std_srvs/srv/Trigger" if kind == "srv" else "test_msgs/action/Fibonacci"))
    try:
        return interface_class(type_name)
    except UnknownMessageType as exc:
        raise AdminRefused(422, "unknown_type", text_of(exc)) from None


def rules_from(config: dict) -> AccessRules:
    """The allow and deny rules of the settings; ValueError naming the setting for a bad entry."""
    return AccessRules(parse_rules(config["ROVER_WEB_ROS_ADMIN_ALLOW"], "ROVER_WEB_ROS_ADMIN_ALLOW"),
                       parse_rules(config["ROVER_WEB_ROS_ADMIN_DENY"], "ROVER_WEB_ROS_ADMIN_DENY"))


class RosAdmin:
    def __init__(self, rover: Rover, estop, oplog: OperatorLog | None = None):
        self.rover = rover
        self.estop = estop
        config = rover.config
        self.mode = config["ROVER_WEB_ROS_ADMIN"]
        self.rules = rules_from(config)
        self.safety_nodes = tuple(config["ROVER_WEB_ROS_ADMIN_SAFETY_NODES"])
        # Made at the first call, not at start (a node, its executor thread and rclpy.action:
        # most servers never get a call from /ros). Off: never, so nothing here reaches the graph.
        self._node: AdminNode | None = None
        self._node_lock = threading.Lock()
        self.oplog = oplog or OperatorLog(rover.db, LOG_KEEP, audit=rover.audit)
        self.goals = GoalBook()

    @property
    def node(self) -> AdminNode:
        with self._node_lock:
            if self._node is None:
                if self.mode == "off" or not self.rover.runtime.running:
                    raise AdminRefused(503, "ros_admin_unavailable", explain("ROS admin is off or the server is "
                                                                             "stopping"))
                self._node = AdminNode(self.rover.runtime)
            return self._node

    def record(self, control: str, label: str, value: Any, result: str, reason: str, client: str) -> None:
        try:
            self.oplog.record(LOG_NAME, control, label, value, result, reason, client)
        except Exception:  # the call happened; a log that cannot be written must not hide that
            log.exception("operator log: cannot record %s %s", control, label)

    def recent(self, limit: int) -> list[dict]:
        return self.oplog.recent(LOG_NAME, limit)

    def _check_estop(self, control: str, label: str, args: Any, client: str) -> None:
        """After the request's own checks (a bad body is still 400): 409 estop_engaged, logged."""
        try:
            self.estop.check_motion()
        except EStopEngaged:
            self.record(control, label, args, "refused", "estop_engaged", client)
            raise

    def _check_rules(self, subjects: list[tuple[str, str]]) -> None:
        refused = self.rules.refusal(subjects)
        if refused is not None:
            raise AdminRefused(403, *refused)

    def parameter_refusal(self, node: str, name: str) -> str | None:
        """Why setting this parameter would be refused whatever the value (for the page), or None."""
        refused = self.rules.refusal(parameter_subjects(node, name))
        return refused[1] if refused else None

    def service_refusal(self, service: str) -> str | None:
        """Why calling this service would be refused by the rules on its name alone (for the page)."""
        refused = self.rules.refusal([("service", service)])
        return refused[1] if refused else None

    def action_refusal(self, action: str, type_name: str) -> str | None:
        refused = self.rules.refusal([("action", action)])
        return refused[1] if refused else navigation_refusal(action, type_name)

    def is_safety_node(self, node: str) -> bool:
        return matches_any(self.safety_nodes, node)

    # --- nodes ---

    def nodes(self) -> list[dict]:
        own = self.node.own_names
        return [n for n in self.node.nodes() if n["name"] not in own]

    def _require_node(self, node: str) -> None:
        if not self.node.node_exists(node):
            raise AdminRefused(404, "unknown_node", explain("no node %(node)s in the ROS graph", node=node))

    # --- parameters ---

    def parameters(self, node: str) -> list[dict]:
        self._require_node(node)
        try:
            return self.node.parameters(node, PARAMETER_TIMEOUT_S)
        except NoAnswer as exc:
            raise AdminRefused(504, "no_answer", explain("%(node)s did not list its parameters: %(why)s",
                                                         node=node, why=text_of(exc))) from None

    def set_parameter(self, node: str, name: str, value: Any, client: str) -> dict:
        label = f"{node} {name}"
        secret = is_secret(name)
        logged = HIDDEN if secret else value
        try:
            self._check_rules(parameter_subjects(node, name))
            if self.is_safety_node(node) and self.estop.engaged:
                raise AdminRefused(409, "estop_engaged", explain("the e-stop is engaged and %(node)s is a safety "
                                                                 "node (ROVER_WEB_ROS_ADMIN_SAFETY_NODES): its "
                                                                 "parameters stay as they are until the e-stop is "
                                                                 "released",
                                                                 node=node))
            params = {p["name"]: p for p in self.parameters(node)}
            if name not in params:
                raise AdminRefused(404, "unknown_parameter", explain("%(node)s has no parameter %(name)s",
                                                                     node=node, name=name))
            try:
                kind, checked = check_value(params[name], value)
            except ParameterRefused as exc:
                raise AdminRefused(exc.status, exc.code, text_of(exc)) from None
            try:
                ok, reason = self.node.set_parameter(node, name, kind, checked, PARAMETER_TIMEOUT_S)
            except NoAnswer as exc:
                raise AdminRefused(504, "no_answer", text_of(exc)) from None
            if not ok:
                raise AdminRefused(
                    409,
                    "refused_by_node",
                    explain(
                        "%(node)s refused %(name)s: %(value)s", node=node, name=name, value=reason or "no reason given"
                    ),
                )
        except AdminRefused as exc:
            # A refusal's message may quote the value ("got 0.3"): for a secret, only the code.
            self.record(
                "set_parameter",
                label,
                logged,
                "invalid" if exc.status == 400 else "refused",
                exc.code if secret else f"{exc.code}: {exc}",
                client,
            )
            raise
        self.record("set_parameter", label, logged, "sent", "set", client)
        return {"node": node, "name": name, "type": kind, "value": checked}

    # --- services ---

    def services(self) -> list[dict]:
        return self.node.services()

    def describe_type(self, package: str, kind: str, name: str) -> dict:
        type_name = f"{package}/{kind}/{name}"
        try:
            cls = interface_class(type_name)
        except UnknownMessageType as exc:
            # An installed interface package without that type: 404; anything else: 422, as for calls.
            missing = is_interface_package(package) if package.isidentifier() else False
            raise AdminRefused(404 if missing else 422, "unknown_type", text_of(exc)) from None
        if kind == "msg":
            return {"type": type_name, "fields": describe(cls)}
        if kind == "srv":
            return {"type": type_name, "request": describe(cls.Request), "response": describe(cls.Response)}
        return {"type": type_name, "goal": describe(cls.Goal), "feedback": describe(cls.Feedback),
                "result": describe(cls.Result)}

    def call_service(self, service: str, type_name: str, request: Any, timeout_s: float, client: str) -> dict:
        from rover_web.ros.convert import message_to_dict

        args = {"type": type_name, "request": scrub(request)}
        try:
            self._check_rules([("service", service)])
            cls = _type_class(type_name, "srv")
            try:
                message = build(cls.Request, request if request is not None else {}, "request")
            except FieldError as exc:
                raise AdminRefused(400, exc.code, text_of(exc)) from None
            self._check_estop("call_service", service, args, client)
            known = self.node.service_types(service)
            if known is None:
                raise AdminRefused(404, "unknown_service", explain("no service %(service)s in the ROS graph",
                                                                   service=service))
            if type_name not in known:
                raise AdminRefused(
                    400,
                    "type_mismatch",
                    explain(
                        "%(service)s is a %(known)s, not %(type_name)s",
                        service=service,
                        known=", ".join(known),
                        type_name=type_name,
                    ),
                )
            self._check_rules([("service", service)] + [("node", n) for n in self.node.serving_nodes(service)])
            try:
                response = self.node.call(cls, service, message, timeout_s)
            except NoAnswer as exc:
                raise AdminRefused(504, "no_answer", text_of(exc)) from None
        except AdminRefused as exc:
            self.record("call_service", service, args, "invalid" if exc.status in (400, 422) else "refused",
                        f"{exc.code}: {exc}", client)
            raise
        plain = message_to_dict(response, 256)
        shown = "(parameter values are not logged)" if service.endswith(VALUE_SERVICES) else str(scrub(plain))[:300]
        self.record("call_service", service, args, "sent", f"response: {shown}", client)
        return plain

    # --- actions ---

    def send_goal(self, action: str, type_name: str, goal: Any, client: str) -> dict:
        args = {"type": type_name, "goal": scrub(goal)}
        try:
            self._check_rules([("action", action)])
            refused_text = navigation_refusal(action, type_name)
            if refused_text:
                raise AdminRefused(403, "navigation_goal", refused_text)
            cls = _type_class(type_name, "action")
            try:
                message = build(cls.Goal, goal if goal is not None else {}, "goal")
            except FieldError as exc:
                raise AdminRefused(400, exc.code, text_of(exc)) from None
            self._check_estop("send_goal", action, args, client)
            self._check_rules([("action", action)]
                              + [("node", n) for n in self.node.serving_nodes(action, action=True)])
            tracked = Goal(None, action, type_name, None, client)
            try:
                sent = self.node.send_goal(cls, action, message, GOAL_TIMEOUT_S, tracked.on_feedback,
                                           tracked.on_status, tracked.on_result)
            except NoAnswer as exc:
                raise AdminRefused(504, "no_answer", text_of(exc)) from None
            if sent is None:
                raise AdminRefused(409, "goal_rejected", explain("%(action)s rejected the goal", action=action))
        except AdminRefused as exc:
            self.record("send_goal", action, args, "invalid" if exc.status in (400, 422) else "refused",
                        f"{exc.code}: {exc}", client)
            raise
        tracked.goal_id, tracked.handle = sent
        self.goals.add(tracked)
        if self.estop.engaged:  # engaged while the goal was on its way: it must not run
            self.node.cancel_goal(tracked.handle, None)
        self.record("send_goal", action, args, "sent", f"accepted as {tracked.goal_id}", client)
        return tracked.snapshot()

    def goal(self, goal_id: str) -> Goal:
        tracked = self.goals.get(goal_id)
        if tracked is None:
            raise AdminRefused(404, "unknown_goal", explain("no goal %(goal_id)s was sent from here (or it is long "
                                                            "finished)",
                                                            goal_id=goal_id))
        return tracked

    def cancel_goal(self, goal_id: str, client: str) -> dict:
        tracked = self.goal(goal_id)
        try:
            answer = self.node.cancel_goal(tracked.handle, CANCEL_TIMEOUT_S)
        except NoAnswer as exc:
            self.record("cancel_goal", tracked.action, {"goal_id": goal_id}, "refused", "no_answer", client)
            raise AdminRefused(504, "no_answer", text_of(exc)) from None
        self.record("cancel_goal", tracked.action, {"goal_id": goal_id},
                    "sent" if answer in ("canceling", "terminated") else "refused", answer, client)
        return {"goal_id": goal_id, "cancel": answer, **{"status": tracked.snapshot()["status"]}}

    def on_estop(self, by: str) -> None:
        """E-stop hook: every goal sent from here that still runs is asked to cancel (not waited for)."""
        for tracked in self.goals.running():
            try:
                self.node.cancel_goal(tracked.handle, None)
                self.record("cancel_goal", tracked.action, {"goal_id": tracked.goal_id}, "sent",
                            "e-stop engaged", by)
            except Exception:
                log.exception("e-stop: cannot cancel goal %s", tracked.goal_id)
