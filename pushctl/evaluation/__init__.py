"""Evaluation: the PD gain search (``pushctl tune-pd``); trials and tables come with issue 6."""
