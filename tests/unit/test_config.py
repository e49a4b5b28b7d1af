import pytest

from rover_web import config
from rover_web.config import ConfigError


def test_defaults_are_valid_and_complete():
    settings = config.load({}, environ={})
    assert settings["ROVER_WEB_MAX_LINEAR_MPS"] == 5.0
    assert settings["ROVER_WEB_CMD_VEL_TOPIC"] == "/cmd_vel"
    assert set(settings) == {config.PREFIX + s.name for s in config.SETTINGS}


def test_environment_overrides_defaults_with_types():
    settings = config.load(environ={"ROVER_WEB_PORT": "8080", "ROVER_WEB_CMD_VEL_STAMPED": "yes",
                                    "ROVER_WEB_PROXY_HOPS": "2",
                                    "ROVER_WEB_TRUSTED_HOSTS": "robot.local, 10.0.0.5",
                                    "ROVER_WEB_LINK_TOPICS": "[\"/odom\", \"/fix\"]"})
    assert settings["ROVER_WEB_PORT"] == 8080
    assert settings["ROVER_WEB_PROXY_HOPS"] == 2 and config.defaults()["ROVER_WEB_PROXY_HOPS"] == 0
    assert settings["ROVER_WEB_CMD_VEL_STAMPED"] is True
    assert settings["ROVER_WEB_TRUSTED_HOSTS"] == ["robot.local", "10.0.0.5"]
    assert settings["ROVER_WEB_LINK_TOPICS"] == ["/odom", "/fix"]


def test_file_then_environment_then_test_config(tmp_path):
    path = tmp_path / "rover.toml"
    path.write_text('ROVER_WEB_PORT = 7000\nROVER_WEB_NODE_NAME = "from_file"\nROVER_WEB_MAX_LINEAR_MPS = 1.5\n')
    settings = config.load({"ROVER_WEB_MAX_LINEAR_MPS": 0.5},
                           environ={"ROVER_WEB_CONFIG": str(path), "ROVER_WEB_PORT": "7001"})
    assert settings["ROVER_WEB_NODE_NAME"] == "from_file"
    assert settings["ROVER_WEB_PORT"] == 7001
    assert settings["ROVER_WEB_MAX_LINEAR_MPS"] == 0.5


@pytest.mark.parametrize("key, value, words", [
    ("ROVER_WEB_PORT", "eighty", "expected an integer"),
    ("ROVER_WEB_PORT", "70000", "from 1 to 65535"),
    ("ROVER_WEB_MAX_LINEAR_MPS", "nan", "finite"),
    ("ROVER_WEB_MAX_LINEAR_MPS", "-1", "from 0"),
    ("ROVER_WEB_CMD_VEL_STAMPED", "maybe", "true or false"),
    ("ROVER_WEB_CMD_VEL_TOPIC", "cmd vel!", "ROS topic name"),
    ("ROVER_WEB_TRUSTED_HOSTS", "[1, 2]", "list of strings"),
    ("ROVER_WEB_MAX_LINAER_MPS", "1", "unknown setting"),
    ("ROVER_WEB_PROXY_HOPS", "-1", "from 0 to 10"),
    ("ROVER_WEB_PROXY_HOPS", "yes", "an integer"),
])
def test_bad_environment_value_names_the_key(key, value, words):
    with pytest.raises(ConfigError) as err:
        config.load(environ={key: value})
    assert str(err.value).startswith(key + ":")
    assert words in str(err.value)
    assert "environment" in str(err.value)


def test_bad_file_names_the_file(tmp_path):
    path = tmp_path / "bad.toml"
    path.write_text("ROVER_WEB_PORT = = 1")
    with pytest.raises(ConfigError, match="not valid TOML"):
        config.load(environ={"ROVER_WEB_CONFIG": str(path)})
    with pytest.raises(ConfigError, match="cannot read"):
        config.load(environ={"ROVER_WEB_CONFIG": str(tmp_path / "missing.toml")})
    path.write_text("ROVER_WEB_PORT = true")
    with pytest.raises(ConfigError, match=r"ROVER_WEB_PORT: expected an integer.*config file"):
        config.load(environ={"ROVER_WEB_CONFIG": str(path)})


def test_the_configuration_doc_documents_every_setting():
    from rover_web.config import ROOT

    readme = (ROOT / "docs" / "configuration.md").read_text()
    missing = [config.PREFIX + s.name for s in config.SETTINGS if f"`{config.PREFIX}{s.name}`" not in readme]
    assert not missing, f"docs/configuration.md does not document {missing}"
