"""Schemathesis hooks for tests/integration/apidocs/test_fuzz.py (loaded through SCHEMATHESIS_HOOKS).

The fuzz must not remove its own access: a call aimed at its own user or its own token is aimed
elsewhere just before it is sent. before_call, because it sees every case of every phase (the
filter_* hooks see only the generated ones, not the coverage phase's).
"""

import os

import schemathesis

KEEP_USER = os.environ.get("FUZZ_KEEP_USER", "admin")
KEEP_TOKEN_ID = int(os.environ.get("FUZZ_KEEP_TOKEN_ID", "-1"))


@schemathesis.hook
def before_call(context, case, kwargs):
    params = case.path_parameters
    if not params:
        return
    if "name" in params and str(params["name"]).strip().lower() == KEEP_USER:
        params["name"] = KEEP_USER + "-not"
    if "token_id" in params and str(params["token_id"]).strip().lstrip("+0") == str(KEEP_TOKEN_ID):
        params["token_id"] = KEEP_TOKEN_ID + 1_000_000
