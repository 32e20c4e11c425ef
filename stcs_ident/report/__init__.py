"""Every renderer: text, Markdown, CSV tables and figures, per result type.

Nothing below this floor imports it; results carry data, these modules render them.
"""
