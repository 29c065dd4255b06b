"""The sweep's own cluster takes work from its own client only: any local user can reach its
port on 127.0.0.1, but a client without the cluster's TLS credentials is refused."""
from __future__ import annotations

import gc
import operator

import pytest

from drape.batch import sweep

#: Seconds a refused client may try before it gives up.
REFUSED_WITHIN = "5s"


@pytest.fixture(scope="module")
def local_cluster():
    """``(client, cluster)`` of the sweep's local cluster, one worker."""
    client, cluster = sweep.open_client(workers=1)
    try:
        yield client, cluster
    finally:
        client.close()
        cluster.close()


def test_the_local_cluster_speaks_tls_on_the_loopback_only(local_cluster):
    client, cluster = local_cluster
    address = cluster.scheduler_address
    assert address.startswith("tls://127.0.0.1:")
    assert all(w.startswith("tls://127.0.0.1:") for w in client.scheduler_info()["workers"])
    assert cluster.security.require_encryption


def test_its_own_client_runs_a_task(local_cluster):
    client, _ = local_cluster
    assert client.submit(operator.add, 2, 3, pure=False).result(timeout=60) == 5


def refusal(address: str, **kwargs) -> Exception | None:
    """What a :class:`distributed.Client` of ``address`` raises (None: it connected)."""
    from distributed import Client

    try:
        Client(address, timeout=REFUSED_WITHIN, **kwargs).close()
    except Exception as exc:
        return exc
    finally:
        # a client that failed to start closes itself when collected: here, not in the middle
        # of the next client's start, where it waits on the lock that start holds
        gc.collect()
    return None


def test_a_client_without_the_credentials_is_refused(local_cluster):
    address = local_cluster[1].scheduler_address
    # as given, without certificates: nothing to offer the scheduler's TLS
    assert isinstance(refusal(address), (OSError, TypeError))
    # the same port in plain TCP: the scheduler expects a TLS handshake
    assert isinstance(refusal(address.replace("tls://", "tcp://")), OSError)


def test_a_client_with_certificates_of_its_own_is_refused(local_cluster):
    from distributed.security import Security

    assert isinstance(refusal(local_cluster[1].scheduler_address, security=Security.temporary()),
                      OSError)
