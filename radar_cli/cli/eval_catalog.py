"""`radar eval-catalog`: de-rendered real photographs against a catalogue's dimensions (thin wrapper over
radar_cli.evaluate.catalogue)."""

from __future__ import annotations

import click

from radar_cli.evaluate.catalogue import evaluate_catalogue, report_json, summary, table
from radar_cli.fileio import write_json


@click.command("eval-catalog")
@click.argument("results", type=click.Path(file_okay=False))
@click.option("--dimensions", required=True, type=click.Path(dir_okay=False),
              help="Catalogue table, TSV or CSV: an object, object_id or id column, height_cm, optional rim_cm, "
                   "body_cm, foot_cm.")
@click.option("--drawings", type=click.Path(file_okay=False), default=None,
              help="Folder of digitised profiles <object>.csv (height_cm,radius_cm from the foot up).")
@click.option("--silhouettes", type=click.Path(file_okay=False), default=None,
              help="Folder of reference silhouettes <result>.png or <object>_<view>.png, in the photo's pixels.")
@click.option("--json", "json_path", type=click.Path(dir_okay=False), default=None, help="Also write the records here.")
def eval_catalog(results: str, dimensions: str, drawings: str | None, silhouettes: str | None,
                 json_path: str | None) -> None:
    """Measure results (folders named <object> or <object>_<view>) against a catalogue: fitted ratios
    body/height, rim/body, foot/body and their errors, pitch, status, reference IoU and profile error."""
    report = evaluate_catalogue(results, dimensions, drawings, silhouettes)
    if report.unmatched_results:
        click.echo(f"results matching no catalogue row ({len(report.unmatched_results)}): "
                   + ", ".join(report.unmatched_results), err=True)
    if report.unmatched_rows:
        click.echo(f"catalogue rows with dimensions and no result ({len(report.unmatched_rows)}): "
                   + ", ".join(report.unmatched_rows), err=True)
    if not report.records:
        click.echo(f"eval-catalog: no result in {results} matches a row of {dimensions}", err=True)
        raise SystemExit(1)
    for record in report.records:
        if record.problem:
            click.echo(f"skipped {record.result}: {record.problem}", err=True)
    click.echo(table(report))
    if json_path:
        write_json(json_path, report_json(report))
    click.echo(summary(report))
    if any(r.problem for r in report.records):
        raise SystemExit(1)
