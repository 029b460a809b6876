"""A polite HTTP client: paced requests, timeouts covering the body, size limits, retries and block detection.

One `HttpClient` talks to one host budget (the Met API and its image host each get their own). Every attempt
reads the whole body under one deadline, so a slow or stalled body counts as a timeout. 5xx, timeouts and
truncated bodies are retried with full-jitter exponential backoff; 429/503 honour Retry-After; a bot-protection
block (403, or a non-JSON body where JSON was expected) is waited out before retrying.
"""

from __future__ import annotations

import email.utils
import json
import random
import re
import threading
import time
from dataclasses import dataclass, field
from typing import Any, Callable, Mapping

import requests
import urllib3

from radar_cli import __version__
from radar_cli.errors import NetworkError

DEFAULT_USER_AGENT = f"radar-cli/{__version__} (research harvester; set --user-agent to name a contact)"
CHUNK_BYTES = 64 * 1024


@dataclass(frozen=True)
class ClientConfig:
    """How one host is talked to."""

    rate: float = 1.0
    """Requests per second (at most one in flight); <= 0 disables pacing."""
    user_agent: str = DEFAULT_USER_AGENT
    """Sent with every request; should name the tool and a contact."""
    timeout: float = 30.0
    """Seconds for one whole attempt: connect, headers and the full body."""
    connect_timeout: float = 5.0
    """Seconds to establish the connection (at most `timeout`)."""
    retries: int = 5
    """Extra attempts after the first for 5xx, 429, timeouts and truncated bodies."""
    connect_retries: int = 1
    """Extra attempts, `connect_wait` apart, when the host cannot be reached at all (connection refused, unknown
    name, connect timeout): a wrong --api-url or a host that is down ends the run in seconds."""
    connect_wait: float = 0.5
    """Seconds between attempts to reach an unreachable host."""
    backoff_base: float = 1.0
    """Full-jitter backoff: sleep uniform(0, min(backoff_cap, backoff_base * 2**attempt)) seconds."""
    backoff_cap: float = 60.0
    """Upper bound of one backoff sleep."""
    max_retry_after: float = 600.0
    """Upper bound of an honoured Retry-After (a longer one is waited this long, then retried)."""
    block_wait: float = 60.0
    """Seconds to wait out a bot-protection block (plus up to half of it again as jitter)."""
    block_retries: int = 3
    """How many blocks in a row are waited out before giving up."""
    max_bytes: int = 64 * 1024 * 1024
    """Largest body accepted; larger bodies raise BodyTooLarge without being read further."""


class FetchError(NetworkError):
    """A request failed after all retries (or with a non-retryable problem)."""


class BodyTooLarge(FetchError):
    """The body is larger than the configured limit."""


class Blocked(FetchError):
    """The host kept answering with a block page."""


@dataclass(frozen=True)
class Reply:
    """A completed HTTP exchange: status, headers and the whole body."""

    url: str
    status: int
    headers: Mapping[str, str]
    body: bytes
    data: Any = None
    """The decoded JSON body when JSON was expected, else None."""


class _Retry(Exception):
    """Internal: this attempt failed in a retryable way; `wait` overrides the backoff when set."""

    def __init__(self, message: str, wait: float | None = None, block: bool = False, connect: bool = False):
        super().__init__(message)
        self.wait = wait
        self.block = block
        self.connect = connect


@dataclass
class Pacer:
    """Spaces request starts at least 1/rate seconds apart (thread-safe)."""

    rate: float
    clock: Callable[[], float] = time.monotonic
    sleep: Callable[[float], None] = time.sleep
    _next: float = 0.0
    _lock: threading.Lock = field(default_factory=threading.Lock)

    def wait(self) -> None:
        """Block until the next request may start."""
        if self.rate <= 0:
            return
        with self._lock:
            now = self.clock()
            if self._next > now:
                self.sleep(self._next - now)
                now = self._next
            self._next = now + 1.0 / self.rate


def parse_retry_after(value: str | None, now: float | None = None) -> float | None:
    """Seconds to wait from a Retry-After header (delta-seconds or HTTP-date); None when absent or invalid."""
    if not value:
        return None
    value = value.strip()
    if value.isdigit():
        return float(value)
    try:
        when = email.utils.parsedate_to_datetime(value)
    except (TypeError, ValueError):
        return None
    return max(0.0, when.timestamp() - (time.time() if now is None else now))


def _unreachable(error: requests.RequestException) -> str | None:
    """Why no connection could be made (the operating system's words, e.g. `Connection refused`), or None when
    the error came after the connection was made (a reset, a read timeout)."""
    reason = error.args[0].reason if error.args and isinstance(error.args[0], urllib3.exceptions.MaxRetryError) \
        else None
    if not isinstance(reason, urllib3.exceptions.ConnectTimeoutError):  # refused, unknown name, connect timeout
        return None
    match = re.search(r"\[Errno -?\d+\] ([^'\")\]]+)", str(reason))
    return match.group(1).strip() if match else type(reason).__name__


def looks_like_json(body: bytes) -> bool:
    """True when the body starts like a JSON object or array (block pages are HTML or plain text)."""
    head = body.lstrip()[:1]
    return head in (b"{", b"[")


def looks_like_html(body: bytes) -> bool:
    """True when the body starts like an HTML page (where a file such as an image was expected)."""
    head = body.lstrip()[:15].lower()
    return head.startswith((b"<html", b"<!doctype html", b"<head", b"<body"))


class HttpClient:
    """Paced, retrying GETs against one host budget.

    Args:
        config: pacing, timeouts, retries and limits.
        session: a requests.Session to reuse (one is created when None).
        sleep: injectable sleep, for tests.
    """

    def __init__(self, config: ClientConfig, session: requests.Session | None = None,
                 sleep: Callable[[float], None] = time.sleep):
        self.config = config
        self.session = session or requests.Session()
        self.session.headers["User-Agent"] = config.user_agent
        self.sleep = sleep
        self.pacer = Pacer(config.rate, sleep=sleep)
        self.requests_sent = 0

    def get(self, url: str, params: Mapping[str, Any] | None = None, expect_json: bool = False,
            headers: Mapping[str, str] | None = None) -> Reply:
        """GET a URL with retries; 2xx/3xx/4xx (other than 403/429) replies are returned, not raised.

        Args:
            url: absolute http(s) URL.
            params: query parameters.
            expect_json: a non-JSON body (or 403) is then treated as a bot-protection block.
            headers: extra request headers (e.g. If-None-Match).

        Returns:
            The reply with its whole body.

        Raises:
            FetchError: retries exhausted, body too large, or blocked too many times in a row.
        """
        if not url.startswith(("http://", "https://")):
            raise FetchError(f"{url}: not an http(s) URL")
        attempt, blocks, unreachable = 0, 0, 0
        while True:
            try:
                return self._attempt(url, params, expect_json, headers)
            except _Retry as e:
                if e.block:
                    blocks += 1
                    if blocks > self.config.block_retries:
                        raise Blocked(f"{url}: blocked {blocks} times in a row ({e})") from None
                    wait = self.config.block_wait * (1.0 + 0.5 * random.random())
                elif e.connect:
                    unreachable += 1
                    if unreachable > self.config.connect_retries:
                        raise FetchError(f"{url}: cannot connect ({e}; tried {unreachable} times)") from None
                    wait = self.config.connect_wait
                else:
                    attempt += 1
                    if attempt > self.config.retries:
                        raise FetchError(f"{url}: {e} (gave up after {attempt} attempts)") from None
                    wait = min(e.wait, self.config.max_retry_after) if e.wait is not None else self._backoff(attempt)
                self.sleep(wait)

    def _backoff(self, attempt: int) -> float:
        """Full-jitter exponential backoff for the given (1-based) retry."""
        return random.uniform(0.0, min(self.config.backoff_cap, self.config.backoff_base * 2 ** (attempt - 1)))

    def _attempt(self, url: str, params: Mapping[str, Any] | None, expect_json: bool,
                 headers: Mapping[str, str] | None) -> Reply:
        """One paced attempt; raises _Retry for retryable failures."""
        self.pacer.wait()
        self.requests_sent += 1
        deadline = time.monotonic() + self.config.timeout
        connect = min(self.config.connect_timeout, self.config.timeout)
        try:
            with self.session.get(url, params=params, headers=headers, stream=True,
                                  timeout=(connect, self.config.timeout)) as r:
                body = self._read_body(r, deadline)
                reply = Reply(r.url, r.status_code, dict(r.headers), body)
        except requests.ConnectTimeout:
            raise _Retry(f"no connection within {connect:g} s", connect=True) from None
        except (requests.Timeout, requests.ConnectionError) as e:
            unreachable = _unreachable(e)
            raise _Retry(unreachable or type(e).__name__, connect=unreachable is not None) from None
        except (requests.RequestException, urllib3.exceptions.HTTPError) as e:  # truncated or undecodable body
            raise _Retry(f"broken body ({type(e).__name__})") from None
        return self._classify(reply, expect_json)

    def _read_body(self, r: requests.Response, deadline: float) -> bytes:
        """Read the whole body under the attempt deadline and the size limit; detect truncation."""
        limit = self.config.max_bytes
        declared = r.headers.get("Content-Length")
        if declared is not None and declared.isdigit() and int(declared) > limit:
            raise BodyTooLarge(f"{r.url}: body of {declared} bytes exceeds the {limit}-byte limit")
        chunks, size = [], 0
        while True:
            # read1 returns what one socket read gives, so a body that trickles in still meets the deadline
            chunk = r.raw.read1(CHUNK_BYTES, decode_content=True)
            if not chunk:
                break
            size += len(chunk)
            if size > limit:
                raise BodyTooLarge(f"{r.url}: body exceeds the {limit}-byte limit")
            if time.monotonic() > deadline:
                raise _Retry(f"body not received within {self.config.timeout:g} s")
            chunks.append(chunk)
        body = b"".join(chunks)
        if declared is not None and declared.isdigit() and len(body) < int(declared) \
                and "Content-Encoding" not in r.headers:
            raise _Retry(f"truncated body ({len(body)} of {declared} bytes)")
        return body

    def _classify(self, reply: Reply, expect_json: bool) -> Reply:
        """Turn retryable statuses and block pages into _Retry; return everything else."""
        status = reply.status
        if status == 429 or status >= 500:
            wait = parse_retry_after(reply.headers.get("Retry-After"))
            raise _Retry(f"HTTP {status}", wait=wait)
        if status == 403:
            raise _Retry("HTTP 403 (block page)", block=True)
        if not expect_json:
            if 200 <= status < 300 and looks_like_html(reply.body):  # a challenge page instead of the file
                raise _Retry(f"HTML body with HTTP {status} (block page)", block=True)
            return reply
        if not looks_like_json(reply.body):
            if 200 <= status < 300:
                raise _Retry(f"non-JSON body with HTTP {status} (block page)", block=True)
            return reply  # e.g. an HTML 404: the caller decides from the status
        try:
            data = json.loads(reply.body.decode("utf-8"))
        except (UnicodeDecodeError, ValueError):
            raise _Retry(f"malformed JSON with HTTP {status}") from None
        return Reply(reply.url, status, reply.headers, reply.body, data)
