"""`radar eval`: score de-rendering results against synthetic ground truth (thin wrapper over
radar_cli.evaluate.scorer)."""

from __future__ import annotations

import click

from radar_cli.errors import NothingToDoError
from radar_cli.evaluate.scorer import evaluate, markdown_table, report_json
from radar_cli.fileio import write_json


@click.command("eval")
@click.option("--pred", required=True, type=click.Path(file_okay=False), help="Results folder (radar derender).")
@click.option("--gt", required=True, type=click.Path(file_okay=False), help="Synthetic set (radar synth).")
@click.option("--split", default="test", show_default=True, help="Split of --gt to score against.")
@click.option("--json", "json_path", type=click.Path(dir_okay=False), default=None, help="Also write scores here.")
@click.option("--allow-missing", is_flag=True,
              help="Do not fail when some ground-truth samples have no result (scoring a subset).")
def eval_cmd(pred: str, gt: str, split: str, json_path: str | None, allow_missing: bool) -> None:
    """Score results with the paper's metrics (Table 2) and print them beside the paper's numbers."""
    report = evaluate(pred, gt, split)
    if not report.scores:
        raise NothingToDoError(f"{pred}: nothing scored against {gt} ({unscored(report)})")
    for item, problem in report.problems:
        click.echo(f"skipped {item}: {problem}", err=True)
    if report.results_without_truth:
        click.echo(f"results without ground truth ({len(report.results_without_truth)}): "
                   + ", ".join(report.results_without_truth), err=True)
    if report.truth_without_results:
        click.echo(f"ground truth without results ({len(report.truth_without_results)}): "
                   + ", ".join(report.truth_without_results[:20])
                   + (" ..." if len(report.truth_without_results) > 20 else ""), err=True)
    click.echo(markdown_table(report))
    if json_path:
        write_json(json_path, report_json(report))
    click.echo(f"eval: {len(report.scores)} scored, {report.skipped} skipped, "
               f"{len(report.truth_without_results)} without results")
    if report.skipped or (report.truth_without_results and not allow_missing) or not report.scores:
        raise SystemExit(1)


def unscored(report) -> str:
    """Why nothing was scored, in a few words (the first unreadable result named)."""
    first = f": {report.problems[0][0]}: {report.problems[0][1]}" if report.problems else ""
    return (f"{len(report.results_without_truth)} result(s) without ground truth, "
            f"{len(report.truth_without_results)} sample(s) without a result, {len(report.problems)} unreadable"
            + first)


eval = eval_cmd  # noqa: A001  (the attribute name COMMANDS registers)
