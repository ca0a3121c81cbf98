"""The live view's paint handshake without a browser: what the page writes back decides whether the
next frame may leave (the browser's side runs in test_live_view.py)."""
from bokeh.document import Document
from bokeh.models import Column

from crest.view.paint_handshake import PaintHandshake


def handshake_in_a_document() -> PaintHandshake:
    handshake = PaintHandshake()
    doc = Document()
    doc.add_root(Column(*handshake.models))
    handshake.install(doc)
    return handshake


def test_a_frame_sent_blocks_the_next_until_the_page_writes_its_number_back():
    handshake = handshake_in_a_document()
    assert handshake.all_painted()                 # nothing sent yet
    handshake.sent()
    number, sent_ms = handshake.frame.text.split()
    assert number == "1" and float(sent_ms) > 0
    assert not handshake.all_painted()
    handshake.painted.text = handshake.frame.text  # what the page's script writes after its paint
    assert handshake.all_painted()


def test_text_that_is_not_a_frame_number_or_a_number_never_sent_does_not_release_frames():
    handshake = handshake_in_a_document()
    handshake.sent()
    handshake.sent()
    for written in ("", "x 1", "-2 0", "1.5 0"):
        handshake.painted.text = written
        assert not handshake.all_painted(), written
    handshake.painted.text = "1 0"
    assert not handshake.all_painted()             # frame 2 is still in flight
    handshake.painted.text = "99 0"                # beyond what was sent: counts as frame 2
    assert handshake.all_painted()
    handshake.sent()
    assert not handshake.all_painted()
