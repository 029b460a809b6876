"""Presenting a results folder: summary and failures tables, the HTML gallery, its server, contact sheets."""
