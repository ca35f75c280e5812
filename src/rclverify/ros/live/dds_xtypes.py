"""The XTypes type objects the monitor's DDS topics announce: the ones Fast DDS
3 (ROS 2 Kilted's default middleware) builds for the same ROS 2 types.

A DDS participant announces, with each reader and writer, the identifiers of
its type (DDS-XTypes 1.3, 7.6.3.2: TypeInformation; an identifier is a hash
of the serialized type object, 7.3.4.9.1).  A participant that meets an
identifier it does not know asks the announcer for the type object (7.6.3.3:
the type lookup service) and checks the object against the identifier.

Cyclone's Python binding builds the type object of a struct with the
"try construct: discard" flag on every sequence and array element, as
DDS-XTypes 7.3.4.4.4 requires; Fast DDS 3 builds ROS 2's types with no
try-construct flag there.  Every type holding a sequence or an array (a
``LaserScan``, an action's feedback, ``ros_discovery_info``) then has two
identifiers, one per vendor, and a Fast DDS participant looks the monitor's
up.  Measured on the ros2_robot example (docs/ros2.md, "Type objects"): the
lookup logs "Inconsistent TypeObject" and, in about one participant in
twenty, leaves that participant without a match for its own action server's
feedback writer for as long as it was watched (25 s): a monitor announcing
Cyclone's objects could disturb the robot it watches.

So the monitor announces the type object Fast DDS builds: Cyclone's, with
no flag on collection elements.  The identifiers then equal Fast DDS's
(checked against real Fast DDS writers of 30 ROS 2 types in
tests/runtime/test_ros2_type_objects.py) and no lookup is made.  Cyclone
accepts such an object from itself and from others because the monitor's
domain allows it (``AllowInvalidTryConstruct``, :data:`.dds.COMPATIBILITY`).
"""
from __future__ import annotations

import functools
from typing import Any


@functools.cache
def _builder() -> Any:
    """The type-object builder: cyclonedds' own, collection elements without flags."""
    from cyclonedds.idl._typesupport.DDS import XTypes as xt  # deferred: start-up (loads cyclonedds and more only when called)
    from cyclonedds.idl._xt_builder import XTBuilder  # deferred: start-up (loads cyclonedds and more only when called)

    plain = {xt.TI_PLAIN_SEQUENCE_SMALL: "seq_sdefn", xt.TI_PLAIN_SEQUENCE_LARGE: "seq_ldefn",
             xt.TI_PLAIN_ARRAY_SMALL: "array_sdefn", xt.TI_PLAIN_ARRAY_LARGE: "array_ldefn"}

    class FastDdsTypeObjects(XTBuilder):
        """XTBuilder with no try-construct flag on collection elements (module docstring)."""

        _type_hash_db: dict[Any, Any] = {}  # this builder's own cache (the base class keeps another)

        @classmethod
        def _xt_type_identifier(cls, name: str, entity: Any, minimal: bool) -> Any:
            tid = super()._xt_type_identifier(name, entity, minimal)
            field = plain.get(int(tid.discriminator)) if tid.discriminator is not None else None
            if field is not None:
                getattr(tid, field).header.element_flags = xt.MemberFlag()
            return tid

        @classmethod
        def _xt_minimal_collection_element(cls, _type: Any, flags: Any) -> Any:
            return super()._xt_minimal_collection_element(_type, xt.TypeFlag())

        @classmethod
        def _xt_complete_collection_element(cls, _type: Any, flags: Any) -> Any:
            return super()._xt_complete_collection_element(_type, xt.TypeFlag())

    return FastDdsTypeObjects


def as_fast_dds(cls: type) -> type:
    """Make the cyclonedds struct ``cls`` (made by ``make_idl_struct``) announce
    Fast DDS's type object for it (module docstring) and return ``cls``.  The
    object is built when a topic of ``cls`` is first made (or its identifier
    first asked for), not before: structs that only read bags never build one."""
    idl: Any = getattr(cls, "__idl__")

    def fill_type_data() -> None:
        if idl._xt_data[0] is not None:
            return
        from cyclonedds.idl._support import Endianness  # deferred: start-up (loads cyclonedds and more only when called)
        info, mapping = _builder().process_type(idl.datatype)
        idl._xt_data = (info, mapping)
        idl._xt_bytedata = (info.serialize(endianness=Endianness.Little, use_version_2=True)[4:],
                            mapping.serialize(endianness=Endianness.Little, use_version_2=True)[4:])

    idl.fill_type_data = fill_type_data  # what every Topic of ``cls`` and ``get_type_id`` call first
    return cls
