"""rosbag2 (MCAP storage) writing and reading, through rosbags; plain file I/O, no executor.

``BagWriter`` writes messages into a bag inside a hidden staging folder beside it
(``<parent>/.<name>.partial/<name>``) and moves it into place when closed, so a crashed run never
leaves a half-written bag under the asked name, and the finished bag's files and metadata carry its
final name (``<name>/<name>.mcap``) as ``ros2 bag record`` would write them. Recording a running
executor is ``navlab.core.record.Recorder``, built on it.
"""

from __future__ import annotations

import contextlib
import json
import os
import shutil
import struct
import tempfile
from collections.abc import Iterator, Sequence
from pathlib import Path
from typing import Any

from rosbags.rosbag2 import Reader, StoragePlugin, Writer
from rosbags.rosbag2.errors import WriterError

from navlab.io.errors import BagError, IoError
from navlab.io.files import machine_memory_bytes, read_bytes_checked, read_text_checked
from navlab.msgs import TYPESTORE, type_name

__all__ = ["GRAPH_KEY", "BagError", "BagWriter", "bag_graph", "bag_topics", "read_bag", "reindex_bag"]

MAX_METADATA_BYTES = 16 << 20  # a rosbag2 metadata.yaml
GRAPH_KEY = "navlab.graph"  # custom-data key of the node/topic graph a navlab recording stores


class BagWriter:
    """Write navlab (rosbags typestore) messages into a new rosbag2 directory with MCAP storage.

    ``write(topic, msg, t_ns)`` adds a connection on a topic's first message; ``t_ns`` is the receive
    time in integer nanoseconds. ``close()`` finishes the bag and renames it to ``path``.
    """

    def __init__(self, path: str | Path) -> None:
        self.path = Path(path)
        if self.path.exists():
            raise BagError(f"{self.path}: already exists; choose a new directory for the recording")
        self._staging = self.path.parent / f".{self.path.name}.partial"
        self._tmp = self._staging / self.path.name
        if self._staging.exists() or self._staging.is_symlink():  # a killed recording: never removed for a new one
            raise BagError(
                f"{self.path}: {self._staging} holds a recording that was killed; recover it with "
                f"`navlab bag reindex {self.path}` (or move it away) before recording under this name"
            )
        try:
            self._staging.mkdir(parents=True)
            self._writer = Writer(self._tmp, version=8, storage_plugin=StoragePlugin.MCAP)
            self._writer.open()
        except (OSError, WriterError) as exc:
            raise BagError(f"{self.path}: cannot start the recording ({exc})") from None
        self._connections: dict[str, Any] = {}
        self.count = 0
        self.closed = False

    def write(self, topic: str, msg: Any, t_ns: int) -> None:
        """Append ``msg`` on ``topic`` at ``t_ns`` (ns); the topic's type is taken from its first message."""
        conn = self._connections.get(topic)
        if conn is None:
            conn = self._connections[topic] = self._writer.add_connection(topic, type_name(msg), typestore=TYPESTORE)
        self._writer.write(conn, t_ns, TYPESTORE.serialize_cdr(msg, type_name(msg)))
        self.count += 1

    def set_custom_data(self, key: str, value: str) -> None:
        """Store ``key: value`` in the bag's metadata (``custom_data``)."""
        self._writer.set_custom_data(key, value)

    def close(self) -> Path:
        """Finish the bag and move it to its final name; returns that path."""
        if not self.closed:
            self.closed = True
            self._writer.close()
            try:
                os.rename(self._tmp, self.path)  # refuses to replace anything but an empty folder
                self._staging.rmdir()
            except OSError as exc:
                raise BagError(
                    f"{self.path}: cannot move the finished recording from {self._tmp} into place "
                    f"({exc.strerror or exc}); it is kept there"
                ) from None
        return self.path

    def __enter__(self) -> BagWriter:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def damaged(path: str | Path, what: str) -> BagError:
    """The one error of every recording reader: ``DIR: damaged recording: what, where; try reindex``."""
    return BagError(f"{path}: damaged recording: {' '.join(what.split())[:300]}; try `navlab bag reindex {path}`")


def _what(exc: BaseException) -> str:
    if isinstance(exc, MemoryError):
        return "a size field claims more memory than the machine has (MemoryError)"
    text = str(exc) if not isinstance(exc, OSError) else (exc.strerror or str(exc))
    return f"{type(exc).__name__}: {text}" if text else type(exc).__name__


def _check_bag_dir(path: Path) -> None:
    """Refuse what is not a rosbag2 directory of regular files before rosbags opens anything (a named pipe
    would block it, a device never end): the folder, its metadata.yaml and every storage file it names."""
    import yaml

    if not path.is_dir():
        if path.exists() or path.is_symlink():
            kind = "a regular file" if path.is_file() else "not a regular file (a pipe, device or socket)"
            raise BagError(f"{path}: is {kind}; expected a rosbag2 directory (the folder holding metadata.yaml)")
        raise BagError(f"{path}: no such rosbag2 directory")
    names = {p.name for p in path.iterdir() if p.suffix in (".mcap", ".db3", ".yaml")}
    meta = path / "metadata.yaml"
    if meta.exists() or meta.is_symlink():
        try:
            info = yaml.safe_load(read_text_checked(meta, what="rosbag2 metadata.yaml", max_bytes=MAX_METADATA_BYTES))
            files = info["rosbag2_bagfile_information"]["relative_file_paths"]
            names |= {str(f) for f in files}
        except IoError as exc:
            raise damaged(path, str(exc)) from None
        except (RecursionError, MemoryError) as exc:
            raise damaged(path, f"metadata.yaml: {_what(exc)}") from None
        except Exception:  # malformed YAML or layout: rosbags' reader names it below (a damaged recording)
            pass
    root = path.resolve()
    for name in sorted(names):
        f = path / name
        if not (f.exists() or f.is_symlink()):
            continue
        real = f.resolve()
        if root not in real.parents:
            raise damaged(path, f"{name} is outside the recording's folder")
        if not real.is_file():
            raise damaged(path, f"{name} is not a regular file (a pipe, device, socket or folder)")


def _reader(path: Path) -> Reader:
    _check_bag_dir(path)
    return Reader(path)


def read_bag(path: str | Path, *, topics: Sequence[str] = ()) -> Iterator[tuple[str, int, Any]]:
    """Yield ``(topic, t_ns, msg)`` from a rosbag2 directory, deserialised to navlab messages.

    Every failure — rosbags', the file system's, a message that does not deserialise — is a BagError
    naming the recording (and the topic where one is known)."""
    where = ""
    try:
        with _reader(Path(path)) as reader:
            conns = [c for c in reader.connections if not topics or c.topic in topics]
            for conn, t_ns, raw in reader.messages(connections=conns):
                where = f" (a {conn.msgtype} message on {conn.topic} at t={t_ns} ns)"
                msg = TYPESTORE.deserialize_cdr(raw, conn.msgtype)
                where = f" (after the message at t={t_ns} ns)"
                yield conn.topic, t_ns, msg
    except BagError:
        raise
    except Exception as exc:  # the reader's boundary: rosbags, zstd, serde, struct, OS, Unicode errors
        raise damaged(path, _what(exc) + where) from None


def bag_topics(path: str | Path) -> dict[str, tuple[str, int]]:
    """``{topic: (type, message count)}`` of a rosbag2 directory."""
    try:
        with _reader(Path(path)) as reader:
            return {c.topic: (c.msgtype, c.msgcount) for c in reader.connections}
    except BagError:
        raise
    except Exception as exc:  # the reader's boundary
        raise damaged(path, _what(exc)) from None


def bag_graph(path: str | Path) -> dict[str, Any] | None:
    """The node/topic graph a navlab recording stored in its metadata (None for other bags)."""
    import yaml

    _check_bag_dir(Path(path))
    meta = Path(path) / "metadata.yaml"
    try:
        info = yaml.safe_load(read_text_checked(meta, what="rosbag2 metadata.yaml", max_bytes=MAX_METADATA_BYTES))
        raw = (info["rosbag2_bagfile_information"].get("custom_data") or {}).get(GRAPH_KEY)
        graph = json.loads(raw) if raw else None
    except Exception as exc:  # the reader's boundary
        raise damaged(path, f"metadata.yaml: {_what(exc)}") from None
    if graph is not None and not _graph_shaped(graph):
        raise damaged(
            path,
            f"metadata.yaml: {GRAPH_KEY} is not a graph "
            "({nodes: [names], topics: {name: {pub: [names], sub: [names]}}})",
        )
    return graph


def _graph_shaped(graph: Any) -> bool:
    def names(v: Any) -> bool:
        return isinstance(v, list) and all(isinstance(x, str) for x in v)

    topics = graph.get("topics", {}) if isinstance(graph, dict) else None
    return (
        isinstance(topics, dict)
        and names(graph.get("nodes", []))
        and all(isinstance(v, dict) and names(v.get("pub")) and names(v.get("sub")) for v in topics.values())
    )


# --- recovering a recording that was killed (ros2 bag reindex) -------------------------------------------

_MCAP_MAGIC = b"\x89MCAP0\r\n"


def _records(buf: bytes | memoryview, pos: int = 0) -> Iterator[tuple[int, memoryview]]:
    """MCAP records ``(opcode, content)`` from ``pos`` until the data ends or a record is cut off."""
    view = memoryview(buf)
    while pos + 9 <= len(view):
        op = view[pos]
        (length,) = struct.unpack_from("<Q", view, pos + 1)
        if op in (0x02, 0x0F) or pos + 9 + length > len(view):  # footer / data end, or truncated by the kill
            return
        yield op, view[pos + 9 : pos + 9 + length]
        pos += 9 + length


def _string(rec: memoryview, pos: int) -> tuple[str, int]:
    (n,) = struct.unpack_from("<I", rec, pos)
    return bytes(rec[pos + 4 : pos + 4 + n]).decode(), pos + 4 + n


def _scan_mcap(path: Path) -> tuple[dict[int, tuple[str, str]], list[tuple[int, int, bytes]]]:
    """Channels ``{id: (topic, schema name)}`` and messages ``(channel, log_time ns, cdr)`` of a possibly
    truncated MCAP file (no summary needed): every complete record up to where the file was cut."""
    from rosbags.rosbag2.storage_mcap import DECOMPRESSORS

    buf = read_bytes_checked(path, what="MCAP file", max_bytes=machine_memory_bytes() // 4)
    if not buf.startswith(_MCAP_MAGIC):
        raise BagError(f"{path}: not an MCAP file")
    schemas: dict[int, str] = {}
    channels: dict[int, tuple[str, str]] = {}
    messages: list[tuple[int, int, bytes]] = []

    def take(records: Iterator[tuple[int, memoryview]]) -> None:
        for op, rec in records:
            if op == 0x03:  # schema: id, name, encoding, data
                (sid,) = struct.unpack_from("<H", rec, 0)
                schemas[sid] = _string(rec, 2)[0]
            elif op == 0x04:  # channel: id, schema id, topic, encoding, metadata
                cid, sid = struct.unpack_from("<HH", rec, 0)
                channels[cid] = (_string(rec, 4)[0], schemas.get(sid, ""))
            elif op == 0x05:  # message: channel, sequence, log time, publish time, data
                cid, _seq, log_time, _pub = struct.unpack_from("<HIQQ", rec, 0)
                messages.append((cid, log_time, bytes(rec[22:])))
            elif op == 0x06:  # chunk: start, end, uncompressed size, crc, compression, records
                size = struct.unpack_from("<Q", rec, 16)[0]
                compression, pos = _string(rec, 28)
                (n,) = struct.unpack_from("<Q", rec, pos)
                data = bytes(rec[pos + 8 : pos + 8 + n])
                if size > machine_memory_bytes() // 4:
                    raise BagError(f"{path}: cannot be recovered: a chunk claims {size} bytes uncompressed")
                try:
                    raw = DECOMPRESSORS[compression](data, size) if compression else data
                except Exception as exc:  # a corrupt chunk: keep what came before it
                    raise BagError(f"{path}: chunk cannot be decompressed ({exc})") from None
                take(_records(raw))

    try:
        take(_records(buf, len(_MCAP_MAGIC)))
    except BagError:
        raise
    except Exception as exc:  # a record that lies about its layout: keep nothing rather than guess
        raise BagError(f"{path}: cannot be recovered: a malformed MCAP record ({_what(exc)})") from None
    return channels, messages


def _free_name(path: Path) -> Path:
    """``path``, or ``path.1``, ``path.2``, ... : the first name that does not exist."""
    k = 0
    while (candidate := path.with_name(path.name + (f".{k}" if k else ""))).exists() or candidate.is_symlink():
        k += 1
    return candidate


def reindex_bag(path: str | Path, out: str | Path | None = None) -> dict[str, Any]:
    """Rebuild a rosbag2 (MCAP) recording that was killed before it was closed, as ``ros2 bag reindex`` does.

    ``path`` is the recording's directory, or the name it would have had: a killed ``BagWriter`` leaves
    its files in ``.<name>.partial/<name>`` beside it. Every complete message written before the kill is
    kept (the last, unwritten chunk is lost). The rebuilt bag is written in a staging folder of its own and
    then moved: into ``out`` (a new directory; ``path`` is left untouched), else into ``path`` — only the
    bag's own ``<name>.mcap`` and ``metadata.yaml`` are renamed into place, the damaged MCAP files are kept
    beside them as ``<file>.damaged``, and nothing else in the folder is touched. Returns
    ``{"path", "topics", "messages", "kept"}``.
    """
    target = Path(path)
    source = target
    if not any(target.glob("*.mcap")):
        source = target.parent / f".{target.name}.partial" / target.name
        if not any(source.glob("*.mcap")):
            raise BagError(f"{target}: no MCAP file here nor in {source} (nothing to reindex)")
    dest = Path(out) if out is not None else target
    if out is not None and (dest.exists() or dest.is_symlink()):
        raise BagError(f"{dest}: already exists; --out must name a new directory")
    channels: dict[int, tuple[str, str]] = {}
    messages: list[tuple[int, int, bytes]] = []
    damaged = sorted(source.glob("*.mcap"))
    for mcap in damaged:
        ch, msgs = _scan_mcap(mcap)
        channels.update(ch)
        messages += msgs
    messages = [m for m in messages if m[0] in channels]  # a message of a channel never declared has no type
    unknown = sorted({t for t in channels.values() if t[1] not in TYPESTORE.types})
    if unknown:
        raise BagError(f"{source}: message types navlab does not know: {', '.join(f'{a} [{b}]' for a, b in unknown)}")
    try:
        dest.parent.mkdir(parents=True, exist_ok=True)
        staging = Path(tempfile.mkdtemp(prefix=f".{dest.name}.reindex-", dir=dest.parent))  # ours alone
    except OSError as exc:
        raise BagError(f"{dest}: cannot write the rebuilt recording ({exc.strerror or exc})") from None
    rebuilt = staging / dest.name
    try:
        writer = Writer(rebuilt, version=8, storage_plugin=StoragePlugin.MCAP)
        writer.open()
        conns = {
            cid: writer.add_connection(topic, msgtype, typestore=TYPESTORE)
            for cid, (topic, msgtype) in sorted(channels.items())
        }
        for cid, t_ns, data in sorted(messages, key=lambda m: m[1]):
            writer.write(conns[cid], t_ns, data)
        writer.close()
        kept = _move_into_place(rebuilt, dest, damaged if out is None else [])
    except (OSError, WriterError) as exc:
        raise BagError(f"{dest}: cannot rewrite the recording ({exc})") from None
    finally:
        shutil.rmtree(staging, ignore_errors=True)
    if out is None and source != target:  # the killed writer's staging folders, if now empty
        for folder in (source, source.parent):
            with contextlib.suppress(OSError):
                folder.rmdir()
    counts: dict[str, int] = {}
    for cid, _t, _d in messages:
        counts[channels[cid][0]] = counts.get(channels[cid][0], 0) + 1
    return {"path": str(dest), "topics": counts, "messages": len(messages), "kept": [str(k) for k in kept]}


def _move_into_place(rebuilt: Path, dest: Path, damaged: list[Path]) -> list[Path]:
    """Move the rebuilt bag's files into ``dest`` (renamed whole when ``dest`` does not exist), keeping each
    ``damaged`` file as ``<dest>/<name>.damaged``; returns where the damaged files were kept."""
    if not dest.exists():
        kept = []
        for f in damaged:  # out of the killed writer's staging folder, into the rebuilt bag
            kept.append(_free_name(rebuilt / f"{f.name}.damaged"))
            os.replace(f, kept[-1])
        rebuilt.rename(dest)
        return [dest / k.name for k in kept]
    if not dest.is_dir():
        raise BagError(f"{dest}: is not a directory")
    kept = []
    for f in damaged:
        kept.append(_free_name(dest / f"{f.name}.damaged"))
        os.replace(f, kept[-1])
    for f in sorted(rebuilt.iterdir()):  # <name>.mcap and metadata.yaml, each renamed atomically
        os.replace(f, dest / f.name)
    return kept
