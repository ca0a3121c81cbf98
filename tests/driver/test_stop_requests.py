"""crest.driver.stop_requests: a stop a signal handler requests in a session is raised at a safe point."""
import pytest

from crest.driver import Terminated, stop_requests


def test_outside_a_session_a_request_is_refused_so_the_handler_raises_at_once():
    assert stop_requests.request(KeyboardInterrupt()) is False
    stop_requests.raise_requested()                      # nothing was kept


def test_in_a_session_the_first_request_is_raised_at_the_next_safe_point_and_only_there():
    with stop_requests.at_safe_points():
        assert stop_requests.request(Terminated()) is True
        assert stop_requests.request(KeyboardInterrupt()) is True      # a later one does not replace it
        with pytest.raises(Terminated):
            stop_requests.raise_requested()
        stop_requests.raise_requested()                  # taken: the next safe point raises nothing


def test_a_request_after_the_last_safe_point_is_raised_when_the_session_ends():
    with pytest.raises(KeyboardInterrupt):
        with stop_requests.at_safe_points():
            stop_requests.request(KeyboardInterrupt())
    stop_requests.raise_requested()


def test_a_session_that_ends_in_an_exception_keeps_it_and_drops_the_request():
    with pytest.raises(ValueError):
        with stop_requests.at_safe_points():
            stop_requests.request(KeyboardInterrupt())
            raise ValueError("the stop under way")
    with stop_requests.at_safe_points():
        stop_requests.raise_requested()                  # the next session starts with nothing requested
