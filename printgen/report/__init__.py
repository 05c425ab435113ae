"""Report: JSON records, plots and the HTML report."""
