"""The overlay readers' Fast DDS profile file (rover_web/ros/dds_profiles.py): what is written, and when
the user's own profile settings are left alone. Fast DDS reading it is tests/integration/overlays/
test_dds_profile.py."""

import xml.etree.ElementTree as ET

import pytest

from rover_web import config, overlays
from rover_web.ros import dds_profiles

NS = {"d": "http://www.eprosima.com/XMLSchemas/fastRTPS_Profiles"}


@pytest.fixture(autouse=True)
def fresh(monkeypatch, tmp_path):
    monkeypatch.setattr(dds_profiles, "_written", None)
    monkeypatch.chdir(tmp_path)  # no DEFAULT_FASTRTPS_PROFILES.xml of the checkout's


def readers(path):
    root = ET.parse(path).getroot()
    return {r.get("profile_name"): (r.get("is_default_profile"), r.findtext("d:historyMemoryPolicy", namespaces=NS),
                                    r.findtext("d:qos/d:data_sharing/d:kind", namespaces=NS))
            for r in root.iterfind("d:profiles/d:data_reader", NS)}


def test_the_overlay_topics_get_dynamic_readers_and_every_other_reader_rmw_s_defaults(tmp_path):
    env = {}
    path = dds_profiles.prepare(["/visualization_marker_array", "scan", "~/footprint", ""], tmp_path / "dds",
                                "rover_web", env)
    assert env == {"FASTRTPS_DEFAULT_PROFILES_FILE": str(path), "RMW_FASTRTPS_USE_QOS_FROM_XML": "1",
                   dds_profiles.OURS: str(path)}
    got = readers(path)
    assert got["rover_web_reader"] == ("true", "PREALLOCATED_WITH_REALLOC", "OFF")
    assert {k: v for k, v in got.items() if k != "rover_web_reader"} == {
        "/rover_web/footprint": (None, "DYNAMIC", "OFF"), "/scan": (None, "DYNAMIC", "OFF"),
        "/visualization_marker_array": (None, "DYNAMIC", "OFF")}
    writer = ET.parse(path).getroot().find("d:profiles/d:data_writer", NS)
    assert writer.get("is_default_profile") == "true"
    assert writer.findtext("d:qos/d:publishMode/d:kind", namespaces=NS) == "SYNCHRONOUS"
    assert writer.findtext("d:historyMemoryPolicy", namespaces=NS) == "PREALLOCATED_WITH_REALLOC"


def test_rmw_s_publication_mode_is_kept():
    assert "<kind>ASYNCHRONOUS</kind>" in dds_profiles.profiles_xml(["/a"], "ASYNCHRONOUS")
    assert "publishMode" not in dds_profiles.profiles_xml(["/a"], "AUTO")


@pytest.mark.parametrize("theirs", ["FASTRTPS_DEFAULT_PROFILES_FILE", "FASTDDS_DEFAULT_PROFILES_FILE",
                                    "RMW_FASTRTPS_USE_QOS_FROM_XML"])
def test_the_user_s_own_profile_settings_are_left_alone(tmp_path, theirs, caplog):
    env = {theirs: "/etc/theirs.xml" if theirs.endswith("FILE") else "0"}
    assert dds_profiles.prepare(["/scan"], tmp_path / "dds", "rover_web", env) is None
    assert env == {theirs: env[theirs]} and not (tmp_path / "dds").exists()
    assert "/scan" in caplog.text and theirs in caplog.text


def test_a_profile_file_in_the_working_directory_is_left_alone_unless_fast_dds_skips_it(tmp_path):
    (tmp_path / "DEFAULT_FASTRTPS_PROFILES.xml").write_text("<dds/>")
    assert dds_profiles.prepare(["/scan"], tmp_path / "dds", "rover_web", {}) is None
    assert dds_profiles.prepare(["/scan"], tmp_path / "dds", "rover_web", {"SKIP_DEFAULT_XML_FILE": "1"})


def test_another_middleware_or_no_overlay_topic_writes_nothing(tmp_path):
    env = {"RMW_IMPLEMENTATION": "rmw_cyclonedds_cpp"}
    assert dds_profiles.prepare(["/scan"], tmp_path / "dds", "rover_web", env) is None
    assert dds_profiles.prepare([], tmp_path / "dds", "rover_web", {}) is None
    assert not (tmp_path / "dds").exists()


def test_the_process_s_own_file_is_kept_and_a_parent_rover_web_s_is_replaced(tmp_path):
    env = {}
    first = dds_profiles.prepare(["/scan"], tmp_path / "one", "rover_web", env)
    # A second app in this process: Fast DDS has read the first file already, and reads no other.
    assert dds_profiles.prepare(["/other"], tmp_path / "two", "rover_web", env) == first
    # A child process inherits the variables: they are rover_web's, not the user's, so it writes its own.
    dds_profiles._written = None
    child = dds_profiles.prepare(["/other"], tmp_path / "two", "rover_web", env)
    assert child == tmp_path / "two" / dds_profiles.FILE_NAME and env["FASTRTPS_DEFAULT_PROFILES_FILE"] == str(child)
    assert "/other" in readers(child)


def test_an_unwritable_folder_leaves_rmw_s_defaults(tmp_path):
    (tmp_path / "file").write_text("")
    env = {}
    assert dds_profiles.prepare(["/scan"], tmp_path / "file" / "dds", "rover_web", env) is None
    assert env == {}


def test_every_robot_s_overlay_topics_are_named():
    robots = [{"name": "alpha", "namespace": "/alpha"}, {"name": "beta", "namespace": "/beta"}]
    names = overlays.reader_topics(config.load({"ROVER_WEB_ROBOTS": robots}))
    assert "/alpha/visualization_marker_array" in names and "/beta/scan" in names
    assert "/beta/local_costmap/costmap" in names and "/alpha/global_costmap/published_footprint" in names
    assert not any(n.startswith("/camera") or "image" in n for n in names)
