"""`radar fetch`: harvest a Met Collection API query (records + validated images + SQLite catalog)."""

from __future__ import annotations

import dataclasses
import sys
from datetime import date
from pathlib import Path
from typing import Literal

import click

from radar_cli.harvest.client import DEFAULT_USER_AGENT, ClientConfig
from radar_cli.harvest.harvester import HarvestConfig, harvest
from radar_cli.harvest.met_api import DEFAULT_API_URL


def _check_date(ctx: click.Context, param: click.Parameter, value: str | None) -> str | None:
    if value is not None:
        try:
            date.fromisoformat(value)
        except ValueError:
            raise click.BadParameter(f"{value!r} is not a YYYY-MM-DD date") from None
    return value


@click.command("fetch")
@click.option("--query", "-q", default="vase", show_default=True, help="Search term.")
@click.option("--out", "-o", type=click.Path(file_okay=False, path_type=Path), required=True,
              help="Output folder (catalog.sqlite, met/<id>.json and met/<id>.jpg).")
@click.option("--limit", type=click.IntRange(min=1), help="Harvest only the first N search results.")
@click.option("--department", type=int, help="Restrict the search to one department id.")
@click.option("--public-domain/--all", default=True, show_default=True,
              help="Keep only public-domain (CC0) objects, or every object with an image.")
@click.option("--image", type=click.Choice(["original", "small"]), default="original", show_default=True,
              help="Full-size primaryImage or ~600 px primaryImageSmall.")
@click.option("--images", "images", type=click.Choice(["primary", "all"]), default="primary", show_default=True,
              help="primary: one image per object (met/<id>.jpg); all: also the record's additionalImages, an "
                   "object with several images in its own folder met/<id>/ (<id>_0.jpg is the primary).")
@click.option("--api-url", default=DEFAULT_API_URL, show_default=True, help="API base URL.")
@click.option("--rate", type=float, default=1.0, show_default=True,
              help="Requests per second, per host (API and image host are paced separately).")
@click.option("--user-agent", default=DEFAULT_USER_AGENT, help="User-Agent naming the tool and a contact.")
@click.option("--since", callback=_check_date, help="YYYY-MM-DD: refetch records of objects changed since.")
@click.option("--ids", "ids_file", type=click.Path(dir_okay=False, exists=True, path_type=Path),
              help="File of object ids (one per line) to harvest instead of searching.")
@click.option("--timeout", type=float, default=30.0, show_default=True, help="Seconds per request attempt.")
@click.option("--block-wait", type=float, default=60.0, show_default=True,
              help="Seconds to wait out a bot-protection block.")
@click.option("--result-cap", type=int, default=10_000, hidden=True, help="Results one search can page.")
@click.option("--page-size", type=int, default=500, hidden=True, help="Search page size.")
@click.option("--progress/--no-progress", default=True, help="Show progress bars.")
def fetch(query: str, out: Path, limit: int | None, department: int | None, public_domain: bool,
          image: Literal["original", "small"], images: Literal["primary", "all"], api_url: str, rate: float,
          user_agent: str, since: str | None, ids_file: Path | None, timeout: float, block_wait: float,
          result_cap: int, page_size: int, progress: bool) -> None:
    """Harvest a Met Collection API query into OUT: search, object records, then validated images.

    Resumable: rerun the same command after a crash or Ctrl-C. Exits 1 when objects or views failed or the API
    could not be reached (a run that harvested nothing leaves no folder behind).
    """
    api_client = ClientConfig(rate=rate, user_agent=user_agent, timeout=timeout, block_wait=block_wait)
    config = HarvestConfig(
        out=out, query=query, limit=limit, department=department, public_domain_only=public_domain,
        image=image, images=images, api_url=api_url, since=since, ids_file=ids_file, page_size=page_size,
        result_cap=result_cap, api_client=api_client,
        image_client=dataclasses.replace(api_client, max_bytes=50 * 1024 * 1024), progress=progress)
    summary = harvest(config)
    click.echo(summary.line())
    if summary.aborted:
        click.echo(f"Error: {summary.aborted}", err=True)
    if summary.interrupted:
        sys.exit(130)
    if summary.failed or summary.views_failed or summary.aborted:
        sys.exit(1)
