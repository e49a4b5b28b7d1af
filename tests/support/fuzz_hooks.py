"""Schemathesis hooks for tests/integration/apidocs/test_fuzz.py (loaded through SCHEMATHESIS_HOOKS).

The fuzz must not remove its own access: a call aimed at its own user or its own token is aimed
elsewhere just before it is sent. before_call, because it sees every case of every phase (the
filter_* hooks see only the generated ones, not the coverage phase's).
"""

import json
import os

import schemathesis
from hypothesis import strategies as st

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


# Names that exist on the server (maps, panels, controls), so generated calls also reach past the
# "no such thing" checks into the code behind them. {path parameter: [values]}, from the test.
REAL = json.loads(os.environ.get("FUZZ_REAL_PATH_VALUES", "{}"))


@schemathesis.hook
def flatmap_path_parameters(context, path_parameters):
    if not path_parameters or context.operation is None or context.operation.path.startswith("/api/users"):
        return st.just(path_parameters)
    choices = {key: REAL[key] for key in path_parameters if REAL.get(key)}
    if not choices:
        return st.just(path_parameters)
    real = st.fixed_dictionaries({key: st.sampled_from(values) for key, values in choices.items()})
    return st.one_of(st.just(path_parameters), real.map(lambda values: {**path_parameters, **values}))
