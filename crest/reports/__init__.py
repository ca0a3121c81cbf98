"""Reports written from analysis results (Markdown and PNG)."""
