"""Groot2's live monitor (bt-run --groot): the tree with its uids, and the ZeroMQ protocol spoken as a client
(bt_humanoid/interop/groot2_tree.py, groot2_server.py, docs/groot2.md)."""

from __future__ import annotations

import json
import socket
import struct
import subprocess
import sys
import threading
import time
import xml.etree.ElementTree as ET

import pytest
from py_trees.common import Status

from bt_humanoid.cli import run_main
from bt_humanoid.interop.btcpp import compile_for_export, mission_document
from bt_humanoid.interop.groot2_tree import groot2_tree
from bt_humanoid.mission.loader import MissionLoader
from bt_humanoid.paths import project_root
from bt_humanoid.skills.base import Skill

zmq = pytest.importorskip("zmq")

ROOT = project_root()
SHORT = """mission: turn and wait
world: apartment
robot: wheeled_humanoid
tree:
  sequence:
    - say: {text: Turning.}
    - move_base: {relative: true, yaw: 60}
    - wait: {seconds: 1}
"""


def _free_port() -> int:
    """A port that is free, and the next one too (the server binds both)."""
    for _ in range(50):
        with socket.socket() as first:
            first.bind(("", 0))
            port = first.getsockname()[1]
            with socket.socket() as second:
                try:
                    second.bind(("", port + 1))
                except OSError:
                    continue
        return port
    raise RuntimeError("no two free ports in a row")


def _tree(name: str):
    file = ROOT / "missions" / name
    compiled = compile_for_export(MissionLoader().load_file(file))
    return groot2_tree(mission_document(file), compiled), compiled


class Client:
    """Groot2's side: a REQ socket asking in protocol 2."""

    def __init__(self, port: int, timeout_ms: int = 5000) -> None:
        self.socket = zmq.Context.instance().socket(zmq.REQ)
        self.socket.setsockopt(zmq.RCVTIMEO, timeout_ms)
        self.socket.setsockopt(zmq.LINGER, 0)
        self.socket.connect(f"tcp://127.0.0.1:{port}")
        self.next_id = 1000

    def ask(self, kind: str, *frames: bytes) -> list[bytes]:
        self.next_id += 1
        self.socket.send_multipart([struct.pack("<BBI", 2, ord(kind), self.next_id), *frames])
        return self.socket.recv_multipart()

    def statuses(self) -> dict[int, int]:
        _, payload = self.ask("S")
        return {uid: status for uid, status in struct.iter_unpack("<HB", payload)}

    def close(self) -> None:
        self.socket.close(linger=0)


# --- the tree ---------------------------------------------------------------------------------------------


def test_every_node_has_a_uid_in_creation_order_and_subtrees_are_instances():
    tree, compiled = _tree("visit_kitchen.yaml")  # calls approach twice and wave once
    root = ET.fromstring(tree.xml)
    uids = [int(element.get("_uid")) for element in root.iter() if element.get("_uid") is not None]
    running = list(compiled.root.iterate())
    assert sorted(uids) == list(range(1, len(running) + 1))
    assert {id(node) for node in tree.nodes} == {id(node) for node in running}
    calls = sorted((e for e in root.iter("SubTree") if e.get("_uid")), key=lambda e: int(e.get("_uid")))
    instances = root.findall("BehaviorTree")[1:]  # in the order they were created, as the calls' uids
    assert [(c.get("ID"), c.get("_fullpath")) for c in calls] == [(b.get("ID"), b.get("_fullpath")) for b in instances]
    assert [c.get("ID") for c in calls] == ["approach", "wave", "approach"]
    # BehaviorTree.CPP numbers a subtree's nodes where it is called: the first instance's root follows its call
    first_call = int(calls[0].get("_uid"))
    assert int(instances[0][0].get("_uid")) == first_call + 1


def test_a_uid_names_the_node_whose_status_it_reports():
    tree, _ = _tree("demo.yaml")
    root = ET.fromstring(tree.xml)
    skills = 0
    for element in root.iter():
        uid = element.get("_uid")
        if uid is None:
            continue
        node = tree.nodes[int(uid) - 1]
        if isinstance(node, Skill):
            skills += 1
            assert element.tag == node.bt_path.rsplit(".", 1)[-1]  # move_base, say, gripper, …
            assert element.get("name") == node.name
    assert skills == 10


def test_the_tree_is_written_as_behaviortree_cpp_publishes_it():
    tree, _ = _tree("demo.yaml")
    root = ET.fromstring(tree.xml)
    assert root.tag == "root" and root.get("BTCPP_format") == "4"
    main = root.find("BehaviorTree")
    assert main.get("ID") == "MainTree" and main.get("_fullpath") == ""
    models = {element.get("ID"): element.tag for element in root.find("TreeNodesModel")}
    # add_builtin_models: BehaviorTree.CPP's own nodes used in the tree are modelled too
    assert models["Sequence"] == "Control" and models["Parallel"] == "Control"
    assert models["move_base"] == "Action" and models["SafetyGuard"] == "Decorator"


# --- the protocol ----------------------------------------------------------------------------------------


@pytest.fixture
def server():
    from bt_humanoid.interop.groot2_server import Groot2Server

    tree, _ = _tree("demo.yaml")
    with Groot2Server(tree, _free_port()) as served:
        client = Client(served.port)
        yield served, client
        client.close()


def test_fulltree_replies_the_header_the_tree_uuid_and_the_xml(server):
    served, client = server
    reply = client.ask("T")
    assert len(reply) == 2
    protocol, kind, request_id = struct.unpack("<BBI", reply[0][:6])
    assert (protocol, chr(kind), request_id) == (2, "T", client.next_id)
    assert len(reply[0]) == 22  # 6 bytes of header and the 16-byte tree UUID
    assert reply[1].decode() == served.tree.xml
    assert client.ask("S")[0][6:] == reply[0][6:], "one tree, one UUID"


def test_status_reports_every_node_and_its_changes(server):
    served, client = server
    nodes = served.tree.nodes
    assert client.statuses() == {uid: 0 for uid in range(1, len(nodes) + 1)}
    nodes[0].status, nodes[5].status, nodes[6].status = Status.RUNNING, Status.SUCCESS, Status.FAILURE
    served.snapshot()
    seen = client.statuses()
    assert (seen[1], seen[6], seen[7], seen[2]) == (1, 2, 3, 0)
    nodes[0].status = Status.INVALID  # halted: BehaviorTree.CPP's "idle, was running"
    served.snapshot()
    assert client.statuses()[1] == 11


def test_recorded_transitions_carry_uid_and_status(server):
    served, client = server
    assert len(client.ask("r", b"start")) == 2  # the header and the server's clock (µs)
    served.tree.nodes[2].status = Status.RUNNING
    served.snapshot()
    _, payload = client.ask("t")
    assert len(payload) == 9
    assert struct.unpack("<HB", payload[6:]) == (3, 1)
    assert client.ask("t")[1] == b"", "transitions are handed out once"


def test_unsupported_and_malformed_requests_get_an_error_reply(server):
    _, client = server
    reply = client.ask("I", json.dumps({"uid": 1}).encode())  # insert a breakpoint
    assert reply[0] == b"error" and b"not supported" in reply[1]
    assert client.ask("?")[0] == b"error"
    client.socket.send_multipart([b"abc"])
    assert client.socket.recv_multipart() == [b"error", b"wrong request header"]
    assert len(client.ask("A")) == 1, "removing all hooks (Groot2 does on leaving) is fine: there are none"


# --- bt-run --groot --------------------------------------------------------------------------------------


@pytest.mark.sim
def test_bt_run_serves_the_tree_and_statuses_while_it_runs(tmp_path):
    mission = tmp_path / "m.yaml"
    mission.write_text(SHORT)
    port = _free_port()
    seen: dict[int, list[int]] = {}
    found: dict[str, str] = {}

    def watch() -> None:
        client = Client(port, timeout_ms=60_000)  # connects before the server binds: ZeroMQ waits for it
        found["xml"] = client.ask("T")[1].decode()
        client.socket.setsockopt(zmq.RCVTIMEO, 2000)
        try:
            while True:
                for uid, status in client.statuses().items():
                    history = seen.setdefault(uid, [])
                    if not history or history[-1] != status:
                        history.append(status)
                time.sleep(0.002)  # hundreds of polls a second: the turn's RUNNING cannot be missed
        except zmq.Again:
            pass  # the run ended and the server with it
        client.close()

    watcher = threading.Thread(target=watch, daemon=True)
    watcher.start()
    assert run_main([str(mission), "--no-live", "--groot", str(port)]) == 0
    watcher.join(timeout=30)
    root = ET.fromstring(found["xml"])
    uid_of = {element.tag: int(element.get("_uid")) for element in root.iter() if element.get("_uid")}
    assert {"say", "move_base", "wait"} <= set(uid_of)
    assert seen[uid_of["move_base"]][-2:] == [1, 2], "the turn seen RUNNING, then SUCCESS"
    assert 1 in seen[uid_of["wait"]]


def test_a_port_in_use_is_one_message_and_exit_2(tmp_path, capsys):
    mission = tmp_path / "m.yaml"
    mission.write_text("mission: talk\ntree:\n  say: {text: hello}\n")
    port = _free_port()
    taken = zmq.Context.instance().socket(zmq.REP)
    taken.bind(f"tcp://*:{port}")
    try:
        assert run_main([str(mission), "--no-live", "--groot", str(port)]) == 2
    finally:
        taken.close(linger=0)
    err = capsys.readouterr().err
    assert f"--groot {port}" in err and "Traceback" not in err


def test_without_pyzmq_groot_says_how_to_install_it(tmp_path, capsys, monkeypatch):
    mission = tmp_path / "m.yaml"
    mission.write_text("mission: talk\ntree:\n  say: {text: hello}\n")
    monkeypatch.setitem(sys.modules, "zmq", None)  # import zmq fails
    assert run_main([str(mission), "--no-live", "--groot"]) == 2
    err = capsys.readouterr().err
    assert "pyzmq" in err and "bt-humanoid[groot]" in err


def test_a_run_without_groot_or_rerun_loads_neither(tmp_path):
    mission = tmp_path / "m.yaml"
    mission.write_text("mission: talk\ntree:\n  say: {text: hello}\n")
    code = (
        "import sys\nfrom bt_humanoid.cli import run_main\n"
        f"assert run_main([{str(mission)!r}, '--no-live']) == 0\n"
        "print(sorted(m for m in ('zmq', 'rerun') if m in sys.modules))\n"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300, check=True)
    assert done.stdout.strip().splitlines()[-1] == "[]"
