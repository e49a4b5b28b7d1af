"""What /ros may write to: allow and deny rules over node, parameter, service and action names. Pure Python.

An entry is `[kind:]pattern`: kind is node, param, service or action (no kind: any of them), the
pattern a shell-style glob matched with fnmatch, case-sensitive as ROS names are; `*` also
matches `/`. A write names several things, each a (kind, name) subject:

  parameter set    ("node", "/base/driver"), ("param", "max_speed"), ("param", "/base/driver/max_speed")
  service call     ("service", "/arm"), and ("node", n) for each node serving it
  action goal      ("action", "/dock"), and ("node", n) for each node serving it

A deny entry matching any subject refuses the write; a non-empty allow list lets through only
writes with a subject it matches. Deny wins. fnmatch (the standard library) rather than regular
expressions: operators write globs in shells every day, and a glob cannot be made slow.
"""

from __future__ import annotations

from dataclasses import dataclass
from fnmatch import fnmatchcase

KINDS = ("node", "param", "service", "action")


@dataclass(frozen=True)
class Rule:
    kind: str | None
    pattern: str

    def matches(self, kind: str, name: str) -> bool:
        return (self.kind is None or self.kind == kind) and fnmatchcase(name, self.pattern)

    def __str__(self) -> str:
        return f"{self.kind}:{self.pattern}" if self.kind else self.pattern


def parse_rules(entries: list[str], setting: str) -> tuple[Rule, ...]:
    """The rules of a setting's entries; ValueError naming the setting and the entry."""
    rules = []
    for entry in entries:
        kind, sep, pattern = entry.partition(":")
        if not sep:
            kind, pattern = None, entry
        elif kind not in KINDS:
            raise ValueError(f"{setting}: {entry!r}: the kind before ':' is one of {', '.join(KINDS)}")
        if not pattern:
            raise ValueError(f"{setting}: {entry!r}: a pattern is needed")
        rules.append(Rule(kind, pattern))
    return tuple(rules)


def matches_any(patterns: tuple[str, ...] | list[str], name: str) -> bool:
    return any(fnmatchcase(name, p) for p in patterns)


def dropped(configured: tuple[Rule, ...], default: tuple[Rule, ...]) -> list[Rule]:
    """The default rules the configured list no longer has. A default counts as kept only when an
    entry says the same (or its kind's, or every kind's, `*`): glob containment in general cannot
    be decided by matching one pattern's text against another, and a warning that says too little
    here would hide a hole."""
    def keeps(rule: Rule, entry: Rule) -> bool:
        if rule == entry:
            return True
        return rule.kind in (None, entry.kind) and set(rule.pattern) == {"*"}

    return [entry for entry in default if not any(keeps(rule, entry) for rule in configured)]


class AccessRules:
    def __init__(self, allow: tuple[Rule, ...], deny: tuple[Rule, ...]):
        self.allow, self.deny = allow, deny

    def refusal(self, subjects: list[tuple[str, str]]) -> tuple[str, str] | None:
        """(code, message) when the write is refused, None when it may go ahead."""
        for rule in self.deny:
            for kind, name in subjects:
                if rule.matches(kind, name):
                    return ("denied", f"{kind} {name} matches {str(rule)!r} in ROVER_WEB_ROS_ADMIN_DENY: "
                            "never written from here")
        if self.allow and not any(rule.matches(kind, name) for rule in self.allow for kind, name in subjects):
            first_kind, first = subjects[0]
            return ("not_allowed", f"{first_kind} {first} is not in ROVER_WEB_ROS_ADMIN_ALLOW, which lists the "
                    "only things written from here")
        return None


def parameter_subjects(node: str, name: str) -> list[tuple[str, str]]:
    return [("param", name), ("node", node), ("param", f"{node}/{name}")]
