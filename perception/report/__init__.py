"""Recognition reports: per clip (JSON, CSV, figures) and per batch (tables, statistics, HTML).

The names ``__init__.pyi`` lists load their module on first use
(``lazy_loader``): ``recognize`` writes a clip's report without importing
the batch report's pandas and statistics, which cost half a second a
process.
"""

import lazy_loader as _lazy

__getattr__, __dir__, __all__ = _lazy.attach_stub(__name__, __file__)
