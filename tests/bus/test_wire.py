"""rmw_zenoh wire conventions, checked against the examples in its design document."""

from __future__ import annotations

import pytest

from cyborg.bus import MessageTypes
from cyborg.bus.wire import (
    ATTACHMENT_SIZE,
    Attachment,
    Durability,
    EntityKind,
    History,
    Qos,
    Reliability,
    data_key,
    dds_type_name,
    domain_id,
    endpoint_token,
    fully_qualified,
    gid,
    mangle,
    node_token,
    unmangle,
)

STRING_HASH = "RIHS01_df668c740482bbd48fb39d76a70dfd4bd59db1288021743503259e948f6b1a18"
ADD_HASH = "RIHS01_e118de6bf5eeb66a2491b5bda11202e7b68f198d6f67922cf30364858239c81a"


def test_dds_type_names() -> None:
    assert dds_type_name("std_msgs/msg/String") == "std_msgs::msg::dds_::String_"
    assert dds_type_name("example_interfaces/srv/AddTwoInts") == \
        "example_interfaces::srv::dds_::AddTwoInts_"


def test_data_keys_from_the_design_document() -> None:
    types = MessageTypes()
    assert data_key(0, "/chatter", "std_msgs/msg/String", types.hash("std_msgs/msg/String")) \
        == f"0/chatter/std_msgs::msg::dds_::String_/{STRING_HASH}"
    assert data_key(0, "/robot1/chatter", "std_msgs/msg/String", STRING_HASH) \
        == f"0/robot1/chatter/std_msgs::msg::dds_::String_/{STRING_HASH}"
    service_hash = types.hash("example_interfaces/srv/AddTwoInts")
    assert data_key(2, "/add_two_ints", "example_interfaces/srv/AddTwoInts", service_hash) \
        == f"2/add_two_ints/example_interfaces::srv::dds_::AddTwoInts_/{ADD_HASH}"


def test_subscription_token_from_the_design_document() -> None:
    token = endpoint_token(2, "aac3178e146ba6f1fc6e6a4085e77f21", 0, 10,
                           EntityKind.SUBSCRIPTION, "", "listener", "/chatter",
                           "std_msgs/msg/String", STRING_HASH, Qos(depth=10))
    assert token == ("@ros2_lv/2/aac3178e146ba6f1fc6e6a4085e77f21/0/10/MS/%/%/listener/"
                     f"%chatter/std_msgs::msg::dds_::String_/{STRING_HASH}/::,10:,:,:,,")


def test_node_token_and_name_mangling() -> None:
    assert node_token(0, "1f", 3, "/robot1/nav", "planner") == \
        "@ros2_lv/0/1f/3/3/NN/%/%robot1%nav/planner"
    assert mangle("/camera/color/image_raw") == "%camera%color%image_raw"
    assert mangle("") == "%" and unmangle("%") == ""
    assert unmangle("%camera%color") == "/camera/color"


@pytest.mark.parametrize(("qos", "text"), [
    (Qos(), "::,:,:,:,,"),
    (Qos(depth=10), "::,10:,:,:,,"),
    (Qos.latched(), ":1:,1:,:,:,,"),
    (Qos(reliability=Reliability.BEST_EFFORT, history=History.KEEP_ALL), "2::2,:,:,:,,"),
    (Qos(durability=Durability.TRANSIENT_LOCAL, deadline=(1, 500)), ":1:,:1,500:,:,,"),
])
def test_qos_strings_leave_defaults_empty(qos: Qos, text: str) -> None:
    assert qos.to_keyexpr() == text


def test_fully_qualified_names() -> None:
    assert fully_qualified("", "chatter") == "/chatter"
    assert fully_qualified("/robot1", "chatter") == "/robot1/chatter"
    assert fully_qualified("robot1/", "cyborg/bt/enabled") == "/robot1/cyborg/bt/enabled"
    assert fully_qualified("/robot1", "/absolute") == "/absolute"
    with pytest.raises(ValueError, match="invalid topic"):
        fully_qualified("", "~private")


def test_gid_is_xxh3_128_of_the_token_little_endian() -> None:
    first = gid("@ros2_lv/0/1f/0/1/MP/%/%/talker/%chatter/x/y/::,:,:,:,,")
    assert len(first) == 16
    assert first == gid("@ros2_lv/0/1f/0/1/MP/%/%/talker/%chatter/x/y/::,:,:,:,,")
    assert first != gid("@ros2_lv/0/1f/0/2/MP/%/%/talker/%chatter/x/y/::,:,:,:,,")
    # Known value of XXH3-128 with seed 0 for b"a", low 64 bits first.
    assert gid("a") == (225219434562328483135862406050043285023).to_bytes(16, "little")


def test_attachment_layout() -> None:
    source = bytes(range(16))
    raw = Attachment(1, 1_700_000_000_123_456_789, source).encode()
    assert len(raw) == ATTACHMENT_SIZE == 33
    assert raw[:8] == (1).to_bytes(8, "little")
    assert raw[8:16] == (1_700_000_000_123_456_789).to_bytes(8, "little")
    assert raw[16] == 0x10 and raw[17:] == source
    assert Attachment.decode(raw) == Attachment(1, 1_700_000_000_123_456_789, source)


@pytest.mark.parametrize("raw", [b"", b"\x00" * 32, b"\x00" * 34, b"\x00" * 16 + b"\x0f" +
                                 b"\x00" * 16])
def test_bad_attachments_are_rejected(raw: bytes) -> None:
    with pytest.raises(ValueError, match="attachment"):
        Attachment.decode(raw)


def test_domain_id_from_environment() -> None:
    assert domain_id({}) == 0
    assert domain_id({"ROS_DOMAIN_ID": " 7 "}) == 7
    for bad in ("-1", "abc", "300"):
        with pytest.raises(ValueError, match=f"ROS_DOMAIN_ID='{bad}'"):
            domain_id({"ROS_DOMAIN_ID": bad})
