"""bench_derender reports both rates (network alone, full export) as positive numbers."""

from __future__ import annotations

from radar_cli.derender.benchmark import bench_derender
from radar_cli.derender.export import ExportConfig


def test_bench_derender_reports_rates(predictor) -> None:
    result = bench_derender(n_images=4, n_export=1, batch_size=2, export=ExportConfig(2, 32), predictor=predictor)
    assert result["network_images_per_s"] > 0 and result["full_images_per_s"] > 0
    assert result["failed"] == 0 and result["image_size"] == 64 and result["model"] == "fake-model"
    assert result["albedo"] == "divided" and result["pitch"] == "network"
