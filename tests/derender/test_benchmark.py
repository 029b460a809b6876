"""bench_derender reports both rates (network alone, full export) as positive numbers."""

from __future__ import annotations

from radar_cli.derender.export.object_folder import ExportConfig
from radar_cli.derender.run.benchmark import bench_derender


def test_bench_derender_reports_rates(predictor) -> None:
    result = bench_derender(n_images=4, n_export=1, batch_size=2, export=ExportConfig(2, 32), predictor=predictor,
                            resolution=64, n_full=3, workers=1)
    assert result["network_images_per_s"] > 0 and result["full_images_per_s"] > 0
    assert result["failed"] == 0 and result["image_size"] == 64 and result["model"] == "fake-model"
    assert result["albedo"] == "divided" and result["pitch"] == "network"
    assert result["resolution"] == [64] and result["photo_side"] == 102  # 1.6 x the output side
    assert 0 <= result["export_state_seconds"] <= result["export_seconds_per_object"]
    assert result["export_write_seconds"] > 0
    assert result["peak_rss_mib"] >= result["rss_before_export_mib"] > 0
    assert result["n_full"] == 3 and result["full_peak_rss_mib"] >= result["full_peak_pss_mib"] > 0
