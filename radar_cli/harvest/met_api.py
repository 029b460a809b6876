"""The Met Collection API endpoints: paged v1.1 search (split past the result cap), object records, changes.

The v1.1 search stops at 10,000 results, so a bigger query is split by department and then by halving the
date range until every part fits. Endpoint paths are settings, so a changed live API needs no code change.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Callable, Iterable

from radar_cli.errors import NetworkError
from radar_cli.harvest.client import HttpClient, Reply

DEFAULT_API_URL = "https://collectionapi.metmuseum.org/public/collection/"
DATE_RANGE = (-8000, 2100)  # objectBeginDate/objectEndDate span of the collection, in years


@dataclass(frozen=True)
class Endpoints:
    """Paths under the API base URL."""

    search: str = "v1.1/search"
    object: str = "v1/objects/{id}"
    objects: str = "v1/objects"
    departments: str = "v1/departments"


def object_ids(data: Any) -> list[int]:
    """The valid ids of a `{total, objectIDs}` body (objectIDs may be null); anything not a positive int dropped."""
    ids = data.get("objectIDs") if isinstance(data, dict) else None
    return [i for i in (ids or []) if isinstance(i, int) and not isinstance(i, bool) and i > 0]


def unique(ids: Iterable[int]) -> list[int]:
    """Ids without repeats, first occurrence kept."""
    return list(dict.fromkeys(ids))


class MetApi:
    """Calls to the Met Collection API through a paced client.

    Args:
        client: the API host's client.
        base_url: API root, ending in `/collection/` for the live API.
        page_size: v1.1 `limit` per page (the API caps it at 500).
        result_cap: results the v1.1 search returns at most for one query.
        endpoints: endpoint paths.
        warn: where warnings (e.g. a part that could not be split further) are reported.
    """

    def __init__(self, client: HttpClient, base_url: str = DEFAULT_API_URL, page_size: int = 500,
                 result_cap: int = 10_000, endpoints: Endpoints = Endpoints(),
                 warn: Callable[[str], None] = print):
        self.client = client
        self.base_url = base_url if base_url.endswith("/") else base_url + "/"
        self.page_size = page_size
        self.result_cap = result_cap
        self.endpoints = endpoints
        self.warn = warn

    def _json(self, path: str, params: dict[str, Any] | None = None) -> Any:
        """GET an endpoint that must answer 200 with JSON."""
        reply = self.client.get(self.base_url + path, params=params, expect_json=True)
        if reply.status != 200 or reply.data is None:
            raise NetworkError(f"{reply.url}: HTTP {reply.status} ({reply.body[:120]!r})")
        return reply.data

    def object(self, object_id: int) -> Reply:
        """The reply for one object record (404/400 replies are returned, not raised)."""
        return self.client.get(self.base_url + self.endpoints.object.format(id=int(object_id)), expect_json=True)

    def departments(self) -> list[int]:
        """All department ids."""
        data = self._json(self.endpoints.departments)
        return [d["departmentId"] for d in data.get("departments", []) if isinstance(d.get("departmentId"), int)]

    def changed_since(self, date: str, department: int | None = None) -> set[int]:
        """Ids whose metadata changed on or after `date` (YYYY-MM-DD)."""
        params: dict[str, Any] = {"metadataDate": date}
        if department is not None:
            params["departmentIds"] = department
        return set(object_ids(self._json(self.endpoints.objects, params)))

    def search(self, query: str, department: int | None = None,
               on_page: Callable[[int], None] = lambda n: None) -> list[int]:
        """Every id matching `query` (objects with images), split into parts below the result cap.

        Args:
            query: the `q` search term.
            department: restrict to one department id.
            on_page: called with the number of ids of each page received (progress).
        """
        params: dict[str, Any] = {"q": query, "hasImages": "true"}
        if department is not None:
            params["departmentId"] = department
        return unique(self._search_part(params, on_page))

    def _page(self, params: dict[str, Any], offset: int) -> tuple[int, list[int]]:
        data = self._json(self.endpoints.search, {**params, "offset": offset, "limit": self.page_size})
        total = data.get("total") if isinstance(data, dict) else None
        return (total if isinstance(total, int) else 0), object_ids(data)

    def _search_part(self, params: dict[str, Any], on_page: Callable[[int], None]) -> list[int]:
        total, ids = self._page(params, 0)
        on_page(len(ids))
        if total > self.result_cap:
            parts = self._split(params)
            if parts:
                return [i for part in parts for i in self._search_part(part, on_page)]
            self.warn(f"search {params}: {total} results but only {self.result_cap} can be paged; "
                      "cannot split further")
        offset = self.page_size
        while ids and offset < min(total, self.result_cap):
            _, page = self._page(params, offset)
            on_page(len(page))
            if not page:
                break
            ids += page
            offset += self.page_size
        if len(ids) < min(total, self.result_cap):
            self.warn(f"search {params}: got {len(ids)} of {total} results; the API may cap results lower "
                      f"than --result-cap {self.result_cap}")
        return ids

    def _split(self, params: dict[str, Any]) -> list[dict[str, Any]]:
        """Sub-queries covering `params`: by department first, then by halving the date range."""
        if "departmentId" not in params:
            return [{**params, "departmentId": d} for d in self.departments()]
        lo, hi = params.get("dateBegin", DATE_RANGE[0]), params.get("dateEnd", DATE_RANGE[1])
        if lo >= hi:
            return []
        mid = (lo + hi) // 2
        return [{**params, "dateBegin": lo, "dateEnd": mid}, {**params, "dateBegin": mid + 1, "dateEnd": hi}]
