"""Presentation of results as data: JSON documents, CSV tables and text summaries, shared by the command
line and the report."""

__all__: list[str] = []
