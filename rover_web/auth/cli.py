"""`flask --app rover_web users ...`, `tokens ...` and `tls self-signed`: run on the robot's computer,
by whoever may read its database, so these commands check no role."""

from __future__ import annotations

import sys
from contextlib import contextmanager
from pathlib import Path

import click
from flask import Flask, current_app
from flask.cli import AppGroup

from rover_web.storage.db import Database, database_path

from .accounts import ROLES, AccountError
from .service import accounts_for

users = AppGroup("users", help="Users who may sign in, and their roles (viewer, operator, admin).")
tokens = AppGroup("tokens", help="API tokens for curl and scripts: Authorization: Bearer <token>.")
tls = AppGroup("tls", help="Certificates for HTTPS.")


@contextmanager
def _accounts():
    db = Database(database_path(current_app))
    try:
        yield accounts_for(db, current_app.config)  # the server's Argon2 parameters
    except AccountError as exc:
        raise click.ClickException(str(exc)) from None
    finally:
        db.close()


def _read_password(from_stdin: bool) -> str:
    if from_stdin:
        line = sys.stdin.readline()
        return line[:-1] if line.endswith("\n") else line
    return click.prompt("Password", hide_input=True, confirmation_prompt=True)


@users.command("add")
@click.argument("name")
@click.option("--role", type=click.Choice(ROLES), required=True)
@click.option("--password-stdin", is_flag=True, help="read the password from the first line of standard input")
def users_add(name: str, role: str, password_stdin: bool) -> None:
    """Add a user; the password is asked for (twice) unless --password-stdin."""
    with _accounts() as accounts:
        accounts.add_user(name, role, _read_password(password_stdin))
    click.echo(f"added {name} ({role})")


@users.command("list")
def users_list() -> None:
    with _accounts() as accounts:
        rows = accounts.users()
    if not rows:
        click.echo("no users; add one with: flask --app rover_web users add NAME --role admin")
    for row in rows:
        click.echo(f"{row['name']}\t{row['role']}\t{row['tokens']} token(s)")


@users.command("remove")
@click.argument("name")
def users_remove(name: str) -> None:
    """Remove a user and revoke their tokens (their signed-in sessions end at their next request)."""
    with _accounts() as accounts:
        accounts.remove_user(name)
    click.echo(f"removed {name}")


@users.command("set-role")
@click.argument("name")
@click.argument("role", type=click.Choice(ROLES))
def users_set_role(name: str, role: str) -> None:
    with _accounts() as accounts:
        accounts.set_role(name, role)
    click.echo(f"{name} is now {role}")


@users.command("set-password")
@click.argument("name")
@click.option("--password-stdin", is_flag=True, help="read the password from the first line of standard input")
def users_set_password(name: str, password_stdin: bool) -> None:
    with _accounts() as accounts:
        accounts.set_password(name, _read_password(password_stdin))
    click.echo(f"password of {name} changed")


@tokens.command("create")
@click.argument("name")
@click.option("--label", default="", help="what the token is for, e.g. 'mission script'")
def tokens_create(name: str, label: str) -> None:
    """Create an API token that acts as user NAME; it is printed once and stored only as a hash."""
    with _accounts() as accounts:
        token_id, token = accounts.create_token(name, label)
    click.echo(f"token {token_id} for {name} (shown once; keep it secret):", err=True)
    click.echo(token)


@tokens.command("list")
def tokens_list() -> None:
    with _accounts() as accounts:
        rows = accounts.tokens()
    for row in rows:
        state = "revoked" if row["revoked_at"] else "active"
        click.echo(f"{row['id']}\t{row['user']}\t{state}\t{row['label']}")


@tokens.command("revoke")
@click.argument("token_id", type=int)
def tokens_revoke(token_id: int) -> None:
    """Revoke token TOKEN_ID (see `tokens list`): it stops working at once."""
    with _accounts() as accounts:
        accounts.revoke_token(token_id)
    click.echo(f"revoked token {token_id}")


@tls.command("self-signed")
@click.option("--host", "hosts", multiple=True, help="a name or address browsers will use (repeatable)")
@click.option("--dir", "directory", type=click.Path(file_okay=False, path_type=Path), default=None,
              help="where to write cert.pem and key.pem (default: the instance folder's tls/)")
@click.option("--new-ca", is_flag=True,
              help="make a new CA even if one is there: every device must then trust the new ca.pem")
def tls_self_signed(hosts: tuple[str, ...], directory: Path | None, new_ca: bool) -> None:
    """Write a self-signed certificate and key into the instance folder, signed by the CA made
    there before (devices that trust it, and noted HSTS, keep working), or a new one."""
    from .tls import NewCANeeded, default_hosts, write_self_signed  # cryptography: ~10 MB a server never needs

    directory = directory or Path(current_app.instance_path) / "tls"
    try:
        cert, key = write_self_signed(directory, list(hosts) or default_hosts(), new_ca=new_ca)
    except NewCANeeded as exc:
        raise click.ClickException(f"{exc}. Nothing was written. Run again with --new-ca to make a new CA; "
                                   "devices that trusted the old ca.pem must then trust the new one, and "
                                   "until they do, HTTPS (and HSTS) keeps them out of the GUI") from None
    click.echo(f"wrote {cert} and {key}; trust {directory / 'ca.pem'} on the devices that browse to it")
    click.echo(f"use them with:\n  export ROVER_WEB_TLS_CERT={cert} ROVER_WEB_TLS_KEY={key}")


def init_cli(app: Flask) -> None:
    for group in (users, tokens, tls):
        app.cli.add_command(group)
