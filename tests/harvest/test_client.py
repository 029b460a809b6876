"""HttpClient against the fake Met server: retries, Retry-After, block pages, body deadline, size limits."""

from __future__ import annotations

import dataclasses
import time

import pytest

from radar_cli.harvest.client import (
    Blocked,
    BodyTooLarge,
    ClientConfig,
    FetchError,
    HttpClient,
    Pacer,
    parse_retry_after,
)

OBJ = "/api/v1/objects/7"


@pytest.fixture
def fast() -> ClientConfig:
    return ClientConfig(rate=0, timeout=0.5, retries=3, backoff_base=0.001, backoff_cap=0.01, block_wait=5.0,
                        block_retries=2, max_bytes=100_000, user_agent="radar-test/1 (test@example.org)")


def client_with_sleeps(config: ClientConfig) -> tuple[HttpClient, list[float]]:
    sleeps: list[float] = []
    return HttpClient(config, sleep=sleeps.append), sleeps


@pytest.mark.parametrize("faults", [("500",), ("503", "500"), ("truncated",), ("malformed",), ("slow",)])
def test_retryable_faults_then_success(met_server, fast, faults):
    met_server.add(7)
    met_server.fault(OBJ, *faults)
    client, sleeps = client_with_sleeps(fast)
    reply = client.get(met_server.api_url + "v1/objects/7", expect_json=True)
    assert reply.status == 200 and reply.data["objectID"] == 7
    assert met_server.hits(OBJ) == len(faults) + 1
    assert len(sleeps) == len(faults) and all(0 <= s <= fast.backoff_cap for s in sleeps)  # full jitter


def test_slow_body_is_cut_at_the_attempt_deadline(met_server, fast):
    met_server.add(7)
    met_server.fault(OBJ, "slow")
    client, _ = client_with_sleeps(dataclasses.replace(fast, retries=0))
    start = time.monotonic()
    with pytest.raises(FetchError, match="not received within"):
        client.get(met_server.api_url + "v1/objects/7", expect_json=True)
    assert time.monotonic() - start < 1.5  # the trickling body would take 2 s


def test_429_honours_retry_after(met_server, fast):
    met_server.add(7)
    met_server.fault(OBJ, "429")
    client, sleeps = client_with_sleeps(fast)
    assert client.get(met_server.api_url + "v1/objects/7", expect_json=True).status == 200
    assert sleeps == [0.0]  # the server said Retry-After: 0


def test_long_retry_after_is_honoured_not_shortened(met_server, fast):
    met_server.add(7)
    met_server.fault(OBJ, "429:120")
    client, sleeps = client_with_sleeps(fast)  # backoff_cap is 0.01 s: Retry-After is not a backoff
    assert client.get(met_server.api_url + "v1/objects/7", expect_json=True).status == 200
    assert sleeps == [120.0]


@pytest.mark.parametrize("fault", ["html403", "html200"])
def test_block_page_is_waited_out(met_server, fast, fault):
    met_server.add(7)
    met_server.fault(OBJ, fault)
    client, sleeps = client_with_sleeps(fast)
    assert client.get(met_server.api_url + "v1/objects/7", expect_json=True).data["objectID"] == 7
    assert len(sleeps) == 1 and fast.block_wait <= sleeps[0] <= 1.5 * fast.block_wait


def test_persistent_block_gives_up(met_server, fast):
    met_server.add(7)
    met_server.fault(OBJ, "html403", "html200", "html403", "html403")
    client, sleeps = client_with_sleeps(fast)
    with pytest.raises(Blocked):
        client.get(met_server.api_url + "v1/objects/7", expect_json=True)
    assert len(sleeps) == fast.block_retries


def test_retries_exhausted(met_server, fast):
    met_server.add(7)
    met_server.fault(OBJ, *["503"] * 10)
    client, sleeps = client_with_sleeps(fast)
    with pytest.raises(FetchError, match="HTTP 503"):
        client.get(met_server.api_url + "v1/objects/7", expect_json=True)
    assert met_server.hits(OBJ) == fast.retries + 1


def test_404_json_is_returned_not_retried(met_server, fast):
    met_server.withdrawn.add(7)
    client, sleeps = client_with_sleeps(fast)
    reply = client.get(met_server.api_url + "v1/objects/7", expect_json=True)
    assert reply.status == 404 and reply.data == {"message": "ObjectID not found"} and not sleeps
    assert met_server.agents == {fast.user_agent}


def test_body_over_the_limit(met_server, fast):
    met_server.add(7, image=b"\xff" * 200_000)
    client, _ = client_with_sleeps(fast)
    with pytest.raises(BodyTooLarge):
        client.get(met_server.url + "/images/7.jpg")


def test_only_http_urls(fast):
    with pytest.raises(FetchError, match="not an http"):
        HttpClient(fast).get("file:///etc/passwd")


def test_pacer_spaces_requests():
    now = [0.0]
    sleeps: list[float] = []

    def sleep(s: float) -> None:
        sleeps.append(s)
        now[0] += s

    pacer = Pacer(rate=2.0, clock=lambda: now[0], sleep=sleep)
    for _ in range(3):
        pacer.wait()
    assert sleeps == [0.5, 0.5]


def test_parse_retry_after():
    assert parse_retry_after("120") == 120.0
    assert parse_retry_after(None) is None and parse_retry_after("soon") is None
    assert parse_retry_after("Wed, 21 Oct 2015 07:28:00 GMT", now=1445412470.0) == pytest.approx(10.0)
