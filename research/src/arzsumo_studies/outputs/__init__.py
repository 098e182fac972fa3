"""Writers of the studies' tables, pages and figures (figures drawn by
:mod:`arzsumo_studies.plots`)."""
