"""Searches beyond the result cap are split by department, then by date range (tested with a fake cap of 5)."""

from __future__ import annotations

from radar_cli.harvest.catalog import open_catalog
from radar_cli.harvest.client import HttpClient
from radar_cli.harvest.harvester import harvest
from radar_cli.harvest.met_api import MetApi


def api_for(met_server, fast_config, warnings: list[str]) -> MetApi:
    return MetApi(HttpClient(fast_config), met_server.api_url, page_size=2, result_cap=met_server.cap,
                  warn=warnings.append)


def test_split_by_department_and_date_finds_everything(met_server, harvest_config):
    met_server.cap = 5
    for i in range(1, 21):
        met_server.add(i, department=6, year=1600 + 10 * i)
    for i in range(21, 31):
        met_server.add(i, department=13, year=-500 + 7 * i)
    config = harvest_config(page_size=2, result_cap=5)
    warnings: list[str] = []
    ids = api_for(met_server, config.api_client, warnings).search("vase")
    assert sorted(ids) == list(range(1, 31)) and len(ids) == 30 and not warnings
    assert met_server.hits("/api/v1/departments") == 1
    summary = harvest(config)
    assert summary.found == 30 and summary.counts["image"] == 30
    with open_catalog(config.out) as catalog:
        assert len(catalog.rows()) == 30


def test_department_search_below_cap_is_not_split(met_server, harvest_config):
    met_server.cap = 5
    for i in range(1, 5):
        met_server.add(i, department=6)
    for i in range(5, 12):
        met_server.add(i, department=13)
    ids = api_for(met_server, harvest_config().api_client, []).search("vase", department=6)
    assert ids == [1, 2, 3, 4] and met_server.hits("/api/v1.1/search") == 2  # two pages of 2


def test_unsplittable_part_warns_and_keeps_the_cap(met_server, harvest_config):
    met_server.cap = 5
    for i in range(1, 8):
        met_server.add(i, department=6, year=1700)
    warnings: list[str] = []
    ids = api_for(met_server, harvest_config().api_client, warnings).search("vase", department=6)
    assert len(ids) == 5 and len(warnings) == 1 and "cannot split further" in warnings[0]


def test_a_lower_cap_than_configured_is_reported(met_server, harvest_config):
    met_server.cap = 5
    for i in range(1, 9):
        met_server.add(i)
    warnings: list[str] = []
    api = MetApi(HttpClient(harvest_config().api_client), met_server.api_url, page_size=2, result_cap=100,
                 warn=warnings.append)
    assert len(api.search("vase")) == 5
    assert len(warnings) == 1 and "got 5 of 8 results" in warnings[0]
