"""Which wire form a service's samples have: the robot's middleware picks
the monitor's reader, the vendor of each sample's writer is checked against it.

ROS 2's middlewares put a service call's identity in different places:

* **rmw_cyclonedds** (Eclipse Cyclone DDS) writes it *in the payload*: each
  request and reply sample starts with the client's request-writer handle
  (``uint64``) and a sequence number (``int64``), then the request's or the
  reply's fields (``cdds_request_header_t``, rmw_cyclonedds ``serdata.hpp``).
  Its endpoints announce no XTypes type information (its ``sertype`` leaves
  type discovery out): they are matched by type name.
* **rmw_fastrtps** (Fast DDS) writes the plain request or reply: the
  request's identity is its DDS sample identity (writer GUID + sequence
  number), and the reply names it as the RTPS *related sample identity*, an
  inline-QoS parameter of the DATA submessage (rmw_fastrtps_shared_cpp
  ``rmw_request.cpp``/``rmw_response.cpp``; DDS-RPC 1.0 section 7.5).
  Cyclone's readers do not hand inline QoS to the application, and the
  sample's sequence number is not in Cyclone's ``SampleInfo``: for the
  monitor such a call has no identity (:mod:`.dds_order`,
  :mod:`.dds_introspection`).

Which form a service topic carries is told by the middleware the robot's
nodes run, as ROS 2 names it: ``RMW_IMPLEMENTATION`` (``rmw_cyclonedds_cpp``:
with the header; ``rmw_fastrtps_cpp``, ROS 2's default when unset, and every
other: without).  The monitor's reader must be of one of the two layouts
before any sample arrives (a Cyclone reader validates each sample against
its type, and one process cannot read one topic name as two types: Cyclone
then delivers neither), so the variable picks the reader; each sample's
writer is then checked against it by the vendor id in its GUID: DDS-RTPS 2.x
(section 8.2.4.2, "GUID prefix") has an implementation put its vendor id in
the first two bytes of the GUID prefix, and both do (Cyclone ``ddsi_init.c``:
0x0110; Fast DDS: 0x010f).  A sample of the other form is counted and not
decoded, never guessed.  The sample's size cannot tell the forms apart (a
request sixteen bytes longer is a valid plain request of many types), nor
the endpoints' USER_DATA (both write ``typehash=...;`` there).  A writer
whose GUID cannot be had (it left between the write and the read) has no
known vendor: its sample is counted, never guessed.
"""
from __future__ import annotations

import os
from typing import Any, Mapping

#: DDS-RTPS vendor ids (the OMG's registry) of the middlewares ROS 2 ships
VENDORS = {b"\x01\x10": "Eclipse Cyclone DDS", b"\x01\x0f": "eProsima Fast DDS", b"\x01\x01": "RTI Connext DDS"}
#: the vendor whose service samples carry rmw_cyclonedds' request header
HEADER_VENDOR = b"\x01\x10"


#: middlewares (``RMW_IMPLEMENTATION``) whose service samples carry rmw_cyclonedds' request header
FRAMED_RMW = ("rmw_cyclonedds_cpp",)


def framed_rmw(env: Mapping[str, str] | None = None) -> bool:
    """Whether the robot's services carry the request header in their samples:
    ``RMW_IMPLEMENTATION`` of ``env`` (default: this process's environment) is
    one of :data:`FRAMED_RMW` (unset: ROS 2's default, rmw_fastrtps_cpp: no)."""
    e = os.environ if env is None else env
    return e.get("RMW_IMPLEMENTATION", "").strip() in FRAMED_RMW


def vendor(guid: bytes) -> str:
    """The name of the DDS implementation that made GUID ``guid`` (16 bytes), or ``vendor 0xNNNN``."""
    return VENDORS.get(bytes(guid[:2]), f"vendor 0x{bytes(guid[:2]).hex()}")


def has_header(guid: bytes) -> bool:
    """Whether a service sample written by writer ``guid`` starts with rmw_cyclonedds' request header."""
    return bytes(guid[:2]) == HEADER_VENDOR


class WriterIds:
    """The GUID of the writer of each sample a reader took, from the sample
    info's publication handle (Cyclone's ``get_matched_publication_data``),
    remembered per (reader, handle).  Used in the DDS thread; ``None`` when
    the writer is no longer matched."""

    def __init__(self, limit: int = 10_000) -> None:
        self._known: dict[tuple[int, int], bytes] = {}
        self.limit = limit

    def of(self, reader: Any, info: Any) -> bytes | None:
        """The 16-byte GUID of the writer of the sample ``info`` describes (taken from ``reader``)."""
        key = (id(reader), int(info.publication_handle))
        hit = self._known.get(key)
        if hit is not None:
            return hit
        try:
            ep = reader.get_matched_publication_data(info.publication_handle)
        except Exception:  # noqa: BLE001 - a writer gone: its samples have no known wire form
            return None
        if ep is None:
            return None
        guid = bytes(ep.key.bytes)
        if len(self._known) >= self.limit:
            self._known.clear()
        self._known[key] = guid
        return guid


__all__ = ["FRAMED_RMW", "HEADER_VENDOR", "VENDORS", "WriterIds", "framed_rmw", "has_header", "vendor"]
