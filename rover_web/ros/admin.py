"""Other nodes' parameters, services and actions, called from request threads.

Everything here lives on a small node of its own (`<app node>_admin`, a SideNode) with its own executor
thread, like the e-stop's GoalCanceller: the clients made for these calls never sit in the main
executor's wait set, so teleop and the event paths do not pay for them. A request thread sends
a call and waits on its future with a timeout; it never spins.

Results are plain values (dicts, lists); failures are the exceptions below. rclpy.action is
imported by the calls that use it, and the node made at the first call (ros_admin/service.py):
a server nobody opens /ros on never loads either (issue 32: idle RSS).
"""

from __future__ import annotations

import threading
import uuid
from collections import OrderedDict
from collections.abc import Callable
from typing import Any

from rcl_interfaces.msg import Parameter as ParameterMsg
from rcl_interfaces.msg import ParameterType, ParameterValue
from rcl_interfaces.srv import DescribeParameters, GetParameters, ListParameters, SetParameters

from rover_web.web.api_messages import explain

from .actions import cancel_if_accepted
from .convert import message_to_dict
from .side_node import SideNode

MAX_CLIENTS = 64  # service and action clients kept for reuse; the oldest is destroyed past this

PARAMETER_TYPES = {ParameterType.PARAMETER_NOT_SET: "not_set", ParameterType.PARAMETER_BOOL: "bool",
                   ParameterType.PARAMETER_INTEGER: "integer", ParameterType.PARAMETER_DOUBLE: "double",
                   ParameterType.PARAMETER_STRING: "string", ParameterType.PARAMETER_BYTE_ARRAY: "byte_array",
                   ParameterType.PARAMETER_BOOL_ARRAY: "bool_array",
                   ParameterType.PARAMETER_INTEGER_ARRAY: "integer_array",
                   ParameterType.PARAMETER_DOUBLE_ARRAY: "double_array",
                   ParameterType.PARAMETER_STRING_ARRAY: "string_array"}
_TYPE_CODES = {name: code for code, name in PARAMETER_TYPES.items()}
_VALUE_FIELDS = {"bool": "bool_value", "integer": "integer_value", "double": "double_value",
                 "string": "string_value", "byte_array": "byte_array_value", "bool_array": "bool_array_value",
                 "integer_array": "integer_array_value", "double_array": "double_array_value",
                 "string_array": "string_array_value"}
GOAL_STATUS = {0: "unknown", 1: "accepted", 2: "executing", 3: "canceling", 4: "succeeded", 5: "canceled",
               6: "aborted"}
CANCEL_CODES = {0: "canceling", 1: "rejected", 2: "unknown_goal", 3: "terminated"}


class NoAnswer(TimeoutError):
    """The other side did not answer within the timeout (or has no server at all)."""


def split_node(full_name: str) -> tuple[str, str]:
    """'/ns/sub/name' -> ('name', '/ns/sub')."""
    namespace, _, name = full_name.rpartition("/")
    return name, namespace or "/"


def _plain_parameter_value(value: ParameterValue) -> Any:
    kind = PARAMETER_TYPES.get(value.type, "not_set")
    if kind == "not_set":
        return None
    raw = getattr(value, _VALUE_FIELDS[kind])
    if kind == "byte_array":
        return [b[0] if isinstance(b, bytes) else int(b) for b in raw]
    if kind.endswith("_array"):
        return list(raw.tolist() if hasattr(raw, "tolist") else raw)
    return raw


def _range(descriptor) -> dict | None:
    for items, kind in ((descriptor.integer_range, "integer"), (descriptor.floating_point_range, "double")):
        if items:
            r = items[0]
            return {"kind": kind, "from": r.from_value, "to": r.to_value, "step": r.step}
    return None


class AdminNode:
    def __init__(self, runtime):
        self._side = SideNode(runtime, "admin")
        self._node = self._side.node
        self._clients: OrderedDict[tuple, Any] = OrderedDict()
        self._lock = threading.Lock()

    def close(self) -> None:
        self._side.close()

    @property
    def own_names(self) -> set[str]:
        prefix = self._node.get_namespace().rstrip("/")
        return {f"{prefix}/{self._node.get_name()}"}

    # --- the graph ---

    def nodes(self) -> list[dict]:
        from rclpy.action.graph import (
            get_action_client_names_and_types_by_node,
            get_action_server_names_and_types_by_node,
        )
        node = self._node
        out = []
        for name, namespace in sorted(node.get_node_names_and_namespaces(), key=lambda p: (p[1], p[0])):
            full = f"{namespace.rstrip('/')}/{name}"

            def listed(getter, name=name, namespace=namespace):
                try:
                    return [{"name": n, "types": list(t)} for n, t in sorted(getter(name, namespace))]
                except Exception:  # the node left between the two queries
                    return []

            services = [s for s in listed(node.get_service_names_and_types_by_node) if "/_action/" not in s["name"]]
            out.append({
                "name": full, "node": name, "namespace": namespace,
                "publishers": [t for t in listed(node.get_publisher_names_and_types_by_node)
                               if not t["name"].endswith("/_action/feedback")
                               and not t["name"].endswith("/_action/status")],
                "subscriptions": listed(node.get_subscriber_names_and_types_by_node),
                "services": services,
                "action_servers": listed(lambda n, ns: get_action_server_names_and_types_by_node(node, n, ns)),
                "action_clients": listed(lambda n, ns: get_action_client_names_and_types_by_node(node, n, ns)),
            })
        return out

    def node_exists(self, full_name: str) -> bool:
        name, namespace = split_node(full_name)
        return (name, namespace) in set(self._node.get_node_names_and_namespaces())

    def services(self) -> list[dict]:
        return [{"name": n, "types": list(t)} for n, t in sorted(self._node.get_service_names_and_types())
                if "/_action/" not in n]

    def service_types(self, service: str) -> list[str] | None:
        for n, types in self._node.get_service_names_and_types():
            if n == service:
                return list(types)
        return None

    def serving_nodes(self, name: str, action: bool = False) -> list[str]:
        """The nodes that serve the service (or action) `name`, by full name."""
        from rclpy.action.graph import get_action_server_names_and_types_by_node
        node = self._node
        out = []
        for n, namespace in node.get_node_names_and_namespaces():
            try:
                served = (get_action_server_names_and_types_by_node(node, n, namespace) if action
                          else node.get_service_names_and_types_by_node(n, namespace))
            except Exception:  # the node left between the two queries
                continue
            if any(s == name for s, _ in served):
                out.append(f"{namespace.rstrip('/')}/{n}")
        return out

    # --- calls ---

    def _client(self, kind: str, cls: type, name: str):
        key = (kind, cls, name)
        with self._lock:
            client = self._clients.get(key)
            if client is not None:
                self._clients.move_to_end(key)
                return client
            if kind == "action":
                from rclpy.action import ActionClient
                client = ActionClient(self._node, cls, name)
            else:
                client = self._node.create_client(cls, name)
            self._clients[key] = client
            while len(self._clients) > MAX_CLIENTS:
                (old_kind, _, _), old = self._clients.popitem(last=False)
                if old_kind == "action":
                    old.destroy()
                else:
                    self._node.destroy_client(old)
        self._side.wake()
        return client

    def _wait(self, future, timeout_s: float, what: str):
        done = threading.Event()
        future.add_done_callback(lambda _f: done.set())
        self._side.wake()
        if not done.wait(timeout_s):
            raise NoAnswer(explain("%(what)s did not answer within %(timeout_s)s s",
                                   what=what, timeout_s=format(timeout_s, "g")))
        return future.result()

    def call(self, srv_cls: type, service: str, request, timeout_s: float) -> Any:
        """Call a service; the response message, or NoAnswer."""
        client = self._client("srv", srv_cls, service)
        if not client.wait_for_service(timeout_sec=min(timeout_s, 2.0)):
            raise NoAnswer(explain("no server for %(service)s answered within %(timeout_s)s s",
                                   service=service, timeout_s=format(min(timeout_s, 2.0), "g")))
        future = client.call_async(request)
        try:
            return self._wait(future, timeout_s, service)
        except NoAnswer:
            client.remove_pending_request(future)
            raise

    # --- parameters ---

    def parameters(self, node: str, timeout_s: float) -> list[dict]:
        """Every parameter of `node`: name, type, value, description, read_only, dynamic_typing, range."""
        listed = self.call(ListParameters, f"{node}/list_parameters", ListParameters.Request(), timeout_s)
        names = sorted(listed.result.names)
        if not names:
            return []
        described = self.call(DescribeParameters, f"{node}/describe_parameters",
                              DescribeParameters.Request(names=names), timeout_s)
        values = self.call(GetParameters, f"{node}/get_parameters", GetParameters.Request(names=names), timeout_s)
        out = []
        for name, descriptor, value in zip(names, described.descriptors, values.values, strict=False):
            out.append({
                "name": name,
                "type": PARAMETER_TYPES.get(value.type, "not_set"),
                "value": _plain_parameter_value(value),
                "description": descriptor.description,
                "additional_constraints": descriptor.additional_constraints,
                "read_only": descriptor.read_only,
                "dynamic_typing": descriptor.dynamic_typing,
                "range": _range(descriptor),
            })
        return out

    def set_parameter(self, node: str, name: str, kind: str, value: Any, timeout_s: float) -> tuple[bool, str]:
        """(successful, reason) as the node answered."""
        pvalue = ParameterValue(type=_TYPE_CODES[kind])
        if kind == "byte_array":
            value = [bytes([v]) for v in value]
        setattr(pvalue, _VALUE_FIELDS[kind], value)
        request = SetParameters.Request(parameters=[ParameterMsg(name=name, value=pvalue)])
        response = self.call(SetParameters, f"{node}/set_parameters", request, timeout_s)
        result = response.results[0]
        return result.successful, result.reason

    # --- actions ---

    def send_goal(self, action_cls: type, action: str, goal, timeout_s: float,
                  on_feedback: Callable[[dict], None], on_status: Callable[[str], None],
                  on_result: Callable[[str, dict], None]) -> tuple[str, Any] | None:
        """Send a goal; (goal_id, handle) once accepted, None if rejected, NoAnswer if no server.
        The callbacks run on the admin executor with plain values."""
        client = self._client("action", action_cls, action)
        if not client.wait_for_server(timeout_sec=timeout_s):
            raise NoAnswer(explain("no action server for %(action)s answered within %(timeout_s)s s",
                                   action=action, timeout_s=format(timeout_s, "g")))

        def feedback(msg) -> None:
            on_feedback(message_to_dict(msg.feedback, 64))

        sending = client.send_goal_async(goal, feedback_callback=feedback)
        try:
            handle = self._wait(sending, timeout_s, action)
        except NoAnswer:
            cancel_if_accepted(sending)
            self._side.wake()
            raise
        if not handle.accepted:
            return None
        goal_id = uuid.UUID(bytes=bytes(handle.goal_id.uuid)).hex
        on_status("accepted")

        def finished(future) -> None:
            try:
                wrapped = future.result()
                on_result(GOAL_STATUS.get(wrapped.status, "unknown"), message_to_dict(wrapped.result, 64))
            except Exception as exc:  # the server went away
                on_result("unknown", {"error": str(exc)[:200]})

        handle.get_result_async().add_done_callback(finished)
        self._side.wake()
        return goal_id, handle

    def cancel_goal(self, handle, timeout_s: float | None) -> str | None:
        """Ask to cancel; with a timeout, wait for the answer ("canceling", "rejected", ...)."""
        future = handle.cancel_goal_async()
        self._side.wake()
        if timeout_s is None:
            return None
        response = self._wait(future, timeout_s, explain("the action server"))
        return CANCEL_CODES.get(response.return_code, "error")
