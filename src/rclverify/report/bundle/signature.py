"""An author's Ed25519 signature over a bundle's manifest.

The manifest lists every member's sha256 and every record carries its own
seal, but a seal is a digest anyone can compute again: a bundle whose
record was swapped and whose seals and manifest were made again passes
``--verify``.  A signature binds the manifest to its
author: ``rclverify bundle --sign KEY`` adds the member ``MANIFEST.sig``,
the Ed25519 signature (RFC 8032) of the exact bytes of ``MANIFEST.json``,
and ``rclverify bundle --verify FILE --key AUTHOR.pub`` checks it against
the public key the assessor pinned (received from the author by a channel
they trust).  Since the manifest hashes every other member, the signature
covers the whole bundle.

What it proves: the manifest, and so every member, is the one the holder
of the private key signed.  What it does not: that the holder is who they
say (the pinning is the assessor's), that the key was not stolen, or
anything about the verdicts beyond what the bundle's own checks say
(docs/integrity.md).

Keys are PEM files: PKCS#8 for the private key, SubjectPublicKeyInfo for
the public one, as ``openssl genpkey -algorithm ed25519`` and ``openssl
pkey -pubout`` write them, or :func:`write_key_pair`.  The cryptography
library does the arithmetic.
"""
from __future__ import annotations

import base64
import hashlib
from pathlib import Path

from rclverify.core.extras import MissingExtra

try:
    from cryptography.exceptions import InvalidSignature
    from cryptography.hazmat.primitives import serialization
    from cryptography.hazmat.primitives.asymmetric.ed25519 import Ed25519PrivateKey, Ed25519PublicKey
except ModuleNotFoundError as _missing:  # the sign extra: one line where a signature is made or checked
    raise MissingExtra("cryptography", "signing or checking a bundle's signature") from _missing

from rclverify.records.store import atomic_write_bytes
from rclverify.report.bundle.manifest import BundleError

#: The member that holds the signature: base64 of the 64 signature bytes, a newline.
SIGNATURE = "MANIFEST.sig"


def _read(path: Path, what: str) -> bytes:
    try:
        return path.read_bytes()
    except OSError as exc:
        raise BundleError([f"{path}: cannot read the {what}: {exc.strerror or exc}"]) from None


def load_private_key(path: Path) -> Ed25519PrivateKey:
    """The Ed25519 private key in the PEM file ``path`` (unencrypted PKCS#8).
    Raises :class:`BundleError` (one line) when it cannot be read or is not one."""
    try:
        key = serialization.load_pem_private_key(_read(path, "private key"), password=None)
    except (ValueError, TypeError) as exc:
        raise BundleError([f"{path}: not an unencrypted PEM private key: {exc}"]) from None
    if not isinstance(key, Ed25519PrivateKey):
        raise BundleError([f"{path}: not an Ed25519 key (a bundle is signed with Ed25519)"])
    return key


def load_public_key(path: Path) -> Ed25519PublicKey:
    """The Ed25519 public key in the PEM file ``path``.  Raises
    :class:`BundleError` (one line) when it cannot be read or is not one."""
    try:
        key = serialization.load_pem_public_key(_read(path, "public key"))
    except (ValueError, TypeError) as exc:
        raise BundleError([f"{path}: not a PEM public key: {exc}"]) from None
    if not isinstance(key, Ed25519PublicKey):
        raise BundleError([f"{path}: not an Ed25519 public key"])
    return key


def fingerprint(key: Ed25519PublicKey) -> str:
    """``SHA256:<hex>`` of the key's 32 raw bytes: what an author reads to an assessor to pin it."""
    raw = key.public_bytes(serialization.Encoding.Raw, serialization.PublicFormat.Raw)
    return "SHA256:" + hashlib.sha256(raw).hexdigest()


def sign(manifest: bytes, key: Ed25519PrivateKey) -> bytes:
    """The ``MANIFEST.sig`` member's bytes for the manifest's bytes ``manifest``."""
    return base64.b64encode(key.sign(manifest)) + b"\n"


def check(manifest: bytes, signature: bytes | None, key: Ed25519PublicKey) -> str:
    """``""`` when ``signature`` (the member's bytes, ``None`` when absent)
    is the pinned ``key``'s signature of ``manifest``, else why not (one line)."""
    if signature is None:
        return f"{SIGNATURE}: missing: the bundle is not signed, and a key was pinned ({fingerprint(key)})"
    try:
        raw = base64.b64decode(signature.strip(), validate=True)
        key.verify(raw, manifest)
    except (ValueError, InvalidSignature):
        return (f"{SIGNATURE}: the signature does not hold for the pinned key {fingerprint(key)}: the manifest was "
                "changed after signing, or another key signed it")
    return ""


def write_key_pair(private: Path) -> Path:
    """Write a new Ed25519 key pair: ``private`` (PKCS#8 PEM, mode 0600) and
    ``<private>.pub`` (SubjectPublicKeyInfo PEM); returns the public key's
    path.  Raises :class:`BundleError` when either exists (never overwritten)."""
    public = private.with_name(private.name + ".pub")
    for p in (private, public):
        if p.exists():
            raise BundleError([f"{p}: exists; a key is never overwritten"])
    key = Ed25519PrivateKey.generate()
    atomic_write_bytes(private, key.private_bytes(serialization.Encoding.PEM, serialization.PrivateFormat.PKCS8,
                                                  serialization.NoEncryption()), mode=0o600)
    atomic_write_bytes(public, key.public_key().public_bytes(serialization.Encoding.PEM,
                                                             serialization.PublicFormat.SubjectPublicKeyInfo),
                       mode=0o644)
    return public


__all__ = ["SIGNATURE", "check", "fingerprint", "load_private_key", "load_public_key", "sign", "write_key_pair"]
